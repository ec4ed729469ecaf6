/* heading.c: Python twin blocks/stages/heading.py; the same operations in the same order. */
#include "stages/heading.h"

#include <math.h>

/* the state's layout (STATE_NAMES; see heading_initial_state): psi_c 0 (rad) */
#define REF_NORM 1    /* reference norm */
#define REF_DIP 2     /* reference dip (rad) */
#define SEEN 3        /* field samples since the start-up began */
#define CAND_NORM 4   /* candidate norm */
#define CAND_DIP 5    /* candidate dip (rad) */
#define CAND_N 6      /* field samples in the candidate */
#define CAND_DOT 7    /* smallest |q.q0| since the candidate began */
#define CAND_Q0 8     /* q0, the orientation then, 4 entries */
#define STEPS 12      /* steps since the start-up began */
#define CAND_START 13 /* the step the candidate began at */
#define GAP 14        /* steps since the last field sample */
#define Q_PREV 15     /* the last step's orientation, 4 entries (0: none yet) */

static const double PI = 3.14159265358979323846;

void heading_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[HEADING_COEF_SIZE])
{
    coef[0] = Ts / params[AF_P_tau_heading];
    coef[1] = Ts / params[AF_P_tau_reference];
    coef[2] = params[AF_P_mag_norm_tol];
    coef[3] = params[AF_P_mag_dip_tol];
    coef[4] = params[AF_P_heading_clip];
    coef[5] = params[AF_P_mag_new_time] / Ts;
    coef[6] = cos(0.5 * params[AF_P_mag_new_angle]);
    coef[7] = 1.0 - exp(-Ts / params[AF_P_tau_heading]);
    coef[8] = 1.0 - exp(-Ts / params[AF_P_tau_reference]);
    coef[9] = params[AF_P_mag_delay]; /* NaN: unset, estimated online */
    hard_iron_coefficients(params, Ts, coef + HARD_IRON_COEF);
    mag_delay_coefficients(params, Ts, coef + MAG_DELAY_COEF);
}

void heading_initial_state(double state[HEADING_STATE_SIZE])
{
    for (int i = 0; i < HEADING_STATE_SIZE; i++)
        state[i] = 0.0;
    state[CAND_DOT] = 1.0;
}

static int steady(double norm, double dip, double ref_norm, double ref_dip, double norm_tol, double dip_tol)
{
    return fabs(norm - ref_norm) <= norm_tol * ref_norm && fabs(dip - ref_dip) <= dip_tol;
}

/* new_reference: a sample outside the reference's tolerance extends the candidate field (or begins
 * one); 1 when the candidate has stayed steady for mag_new_time while the sensor turned through
 * mag_new_angle: the heading estimator then starts afresh */
static int new_reference(double *state, const double *coef, Quat q, double norm, double dip)
{
    double norm_tol = coef[2], dip_tol = coef[3], steps = coef[5], cos_half = coef[6];
    if (state[CAND_N] > 0.0 && steady(norm, dip, state[CAND_NORM], state[CAND_DIP], norm_tol, dip_tol)) {
        state[CAND_N] += 1.0;
        state[CAND_NORM] += (norm - state[CAND_NORM]) / state[CAND_N];
        state[CAND_DIP] += (dip - state[CAND_DIP]) / state[CAND_N];
        double dot = 0.0;
        dot += q.w * state[CAND_Q0];
        dot += q.x * state[CAND_Q0 + 1];
        dot += q.y * state[CAND_Q0 + 2];
        dot += q.z * state[CAND_Q0 + 3];
        double turned = fabs(dot);
        state[CAND_DOT] = turned < state[CAND_DOT] ? turned : state[CAND_DOT];
        if (state[STEPS] - state[CAND_START] + 1.0 >= steps && state[CAND_DOT] <= cos_half) {
            state[CAND_N] = 0.0;
            return 1;
        }
        return 0;
    }
    state[CAND_NORM] = norm, state[CAND_DIP] = dip, state[CAND_N] = 1.0, state[CAND_DOT] = 1.0;
    state[CAND_START] = state[STEPS];
    quat_store(q, state + CAND_Q0);
    return 0;
}

/* field_sample: the field m (earth frame, turned by psi_c; its horizontal norm > 0) taken into
 * psi_c and the reference; whether it was used */
static int field_sample(double *state, const double *coef, Quat q, Vec3 m, double horizontal)
{
    double clip = coef[4];
    double norm = sqrt(horizontal * horizontal + m.z * m.z);
    double dip = atan2(-m.z, horizontal);
    double gap = state[GAP];
    state[GAP] = 0.0;
    if (state[SEEN] == 0.0)
        state[STEPS] = 1.0;
    state[SEEN] += 1.0;
    int start = 1.0 / state[STEPS] > coef[7]; /* within tau_heading of the start */
    int ok = 0;
    if (!start) {
        ok = steady(norm, dip, state[REF_NORM], state[REF_DIP], coef[2], coef[3]);
        if (ok) {
            state[CAND_N] = 0.0;
        } else if (new_reference(state, coef, q, norm, dip)) {
            state[SEEN] = 1.0, state[STEPS] = 1.0, start = 1; /* a proven field: start afresh */
        }
    }
    if (start) { /* running means, every sample */
        ok = 1;
        state[0] += atan2(m.x, m.y) / state[SEEN];
        state[REF_NORM] += (norm - state[REF_NORM]) / state[SEEN];
        state[REF_DIP] += (dip - state[REF_DIP]) / state[SEEN];
    } else if (ok) { /* first-order pulls over the time since the last field sample */
        double error = atan2(m.x, m.y);
        double low = error > -clip ? error : -clip;
        state[0] += pull(gap, coef[0], coef[7]) * (low < clip ? low : clip);
        double a_reference = pull(gap, coef[1], coef[8]);
        state[REF_NORM] += a_reference * (norm - state[REF_NORM]);
        state[REF_DIP] += a_reference * (dip - state[REF_DIP]);
    }
    return ok;
}

/* step_turn: the rotation vector (rad, sensor frame) from q_prev to q */
static Vec3 step_turn(Quat q_prev, Quat q)
{
    Quat d = quat_multiply(quat_conjugate(q_prev), q);
    if (d.w < 0.0)
        d = (Quat){-d.w, -d.x, -d.y, -d.z};
    double s = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    double k = s > 0.0 ? 2.0 * atan2(s, d.w) / s : 2.0;
    return (Vec3){k * d.x, k * d.y, k * d.z};
}

/* turned_back: q turned back in the sensor frame by steps times the last step's rotation turn (rad) */
static Quat turned_back(Quat q, Vec3 turn, double steps)
{
    return quat_multiply(q, rotvec_quat(-steps * turn.x, -steps * turn.y, -steps * turn.z));
}

/* the heading correction psi (rad) as a turn about earth up, applied to q */
static Quat about_up(double psi, Quat q)
{
    double half = 0.5 * psi;
    return quat_multiply((Quat){cos(half), 0.0, 0.0, sin(half)}, q);
}

Quat heading_step(double state[HEADING_STATE_SIZE], const double coef[HEADING_COEF_SIZE], Quat q, Vec3 m_sensor,
                  int *ok)
{
    state[GAP] += 1.0;
    if (state[SEEN] > 0.0)
        state[STEPS] += 1.0;
    *ok = 0;
    int online = isnan(coef[9]);
    if (!online)
        state[MAG_DELAY_IN_USE] = coef[9];
    const double *delay_coef = coef + MAG_DELAY_COEF;
    Quat q_prev = quat_load(state + Q_PREV);
    Vec3 turn = {0.0, 0.0, 0.0}; /* the last step's rotation (rad), wanted online or for a given delay */
    if ((online || coef[9] != 0.0) && fabs(q_prev.w) + fabs(q_prev.x) + fabs(q_prev.y) + fabs(q_prev.z) > 0.0)
        turn = step_turn(q_prev, q);
    if (online)
        mag_delay_turn(state + MAG_DELAY, delay_coef, turn);
    double n2 = m_sensor.x * m_sensor.x + m_sensor.y * m_sensor.y + m_sensor.z * m_sensor.z;
    if (isfinite(n2) && n2 > 0.0) { /* a field sample (not NaN: missing, not all 0: none) */
        int proven;
        m_sensor = hard_iron_step(state + HARD_IRON, coef + HARD_IRON_COEF, m_sensor, state[GAP], coef[2], coef[5],
                                  &proven);
        if (proven) { /* a field freed of (or back without) an offset: start afresh from it */
            state[SEEN] = 0.0;
            mag_delay_restart(state + MAG_DELAY);
        }
        double steps = state[MAG_DELAY_IN_USE] / delay_coef[0];
        Quat q_field = steps != 0.0 ? turned_back(q, turn, steps) : q;
        Vec3 m = quat_rotate(about_up(state[0], q_field), m_sensor);
        double horizontal = sqrt(m.x * m.x + m.y * m.y);
        if (horizontal > 0.0) /* a field with a heading */
            *ok = field_sample(state, coef, q, m, horizontal);
        if (online) {
            Vec3 rate = {turn.x / delay_coef[0], turn.y / delay_coef[0], turn.z / delay_coef[0]};
            mag_delay_field_sample(state + MAG_DELAY, delay_coef, m_sensor, rate, *ok);
        }
    }
    quat_store(q, state + Q_PREV);
    if (fabs(state[0]) > PI)
        state[0] = atan2(sin(state[0]), cos(state[0]));
    return about_up(state[0], q);
}
