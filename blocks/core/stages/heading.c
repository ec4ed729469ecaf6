/* heading.c: heading from the magnetometer with its guard (documented in blocks/stages/heading.py). */
#include "stages/heading.h"

#include <math.h>
#include <string.h>

#define STATE_FIELD(name, dims) AF_FIELD(AfHeading, name)
const AfField HEADING_STATE_FIELDS[] = {HEADING_FIELDS(STATE_FIELD)};
const size_t HEADING_N_FIELDS = sizeof HEADING_STATE_FIELDS / sizeof HEADING_STATE_FIELDS[0];

int heading_coefficients(const double params[AF_N_PARAMS], double Ts, AfHeadingCoef *coef)
{
    double q = 0.5 * params[AF_P_delta_n] * params[AF_P_delta_n];
    coef->q_psi = q;
    coef->r_drift = params[AF_P_tau_heading] * params[AF_P_tau_heading] * q;
    coef->q_rate = params[AF_P_sigma_motion] * params[AF_P_sigma_motion] / params[AF_P_tau_reference];
    coef->block_steps = fmax(1.0, round(DRIFT_BLOCK_TAUS * params[AF_P_tau_heading] / Ts));
    coef->a_block = coef->block_steps * Ts / params[AF_P_tau_reference];
    coef->rate_max = params[AF_P_heading_drift];
    coef->rate_left = params[AF_P_sigma_motion];
    coef->rate_heading = Ts / params[AF_P_tau_heading];
    coef->rate_reference = Ts / params[AF_P_tau_reference];
    coef->a_heading = 1.0 - exp(-Ts / params[AF_P_tau_heading]);
    coef->a_reference = 1.0 - exp(-Ts / params[AF_P_tau_reference]);
    double tau_guard = params[AF_P_tau_mag_guard];
    coef->guard_online = isnan(tau_guard) ? 1.0 : 0.0;
    coef->rate_guard = isnan(tau_guard) ? 0.0 : Ts / tau_guard;
    coef->a_guard = isnan(tau_guard) ? 0.0 : 1.0 - exp(-Ts / tau_guard);
    coef->norm_tol = params[AF_P_mag_norm_tol];
    coef->dip_tol = params[AF_P_mag_dip_tol];
    coef->clip = params[AF_P_heading_clip];
    coef->new_steps = params[AF_P_mag_new_time] / Ts;
    coef->cos_half_turn = cos(0.5 * params[AF_P_mag_new_angle]);
    coef->delay = params[AF_P_mag_delay];
    hard_iron_coefficients(params, Ts, &coef->hard_iron);
    mag_delay_coefficients(params, Ts, &coef->mag_delay);
    return af_finite(coef, sizeof *coef, &coef->delay) ? 0 : -1;
}

void heading_initial_state(AfHeading *state)
{
    memset(state, 0, sizeof *state);
    state->cand_dot = 1.0;
}

/* followed: the drift rate psi_c follows (rad/s): the part of the estimate beyond rate_left (the pull
 * follows that alone) and its s.d., once it is DRIFT_SIGMAS of its s.d. from 0 */
static double followed(double rate, double var_rate, const AfHeadingCoef *coef)
{
    double sd = sqrt(var_rate), left = coef->rate_left > sd ? coef->rate_left : sd;
    if (!(fabs(rate) > DRIFT_SIGMAS * sd))
        return 0.0;
    return rate > left ? rate - left : rate < -left ? rate + left : 0.0;
}

/* restart: the drift estimate begun afresh from the next block (its level unknown, blocks = 0); its
 * rate kept, or with afresh set (a field that was not what it seemed) learnt anew with its noise measure */
static void restart(AfHeading *state, const AfHeadingCoef *coef, int afresh)
{
    state->blocks = 0.0, state->blk_n = 0.0, state->blk_sum = 0.0, state->blk_steps = 0.0, state->unwrapped = 0.0;
    if (afresh) {
        state->rate = 0.0;
        state->var_rate = coef->rate_max * coef->rate_max;
        state->d2[1] = 0.0;
        state->follow = 0.0;
    }
}

/* wrapped: an angle (rad) within (-3 pi, 3 pi) brought within [-pi, pi] */
static double wrapped(double a)
{
    return a > AF_PI ? a - 2.0 * AF_PI : a < -AF_PI ? a + 2.0 * AF_PI : a;
}

/* second_difference: the |second difference| d2 (rad) of three block means into the measure at
 * measure[0] of measure[1] such differences: taken where larger than the measure, otherwise into its
 * running mean, a difference's weight at the least a */
static void second_difference(double measure[2], double d2, double a)
{
    measure[1] += 1.0;
    double w = 1.0 / measure[1] > a ? 1.0 / measure[1] : a;
    measure[0] = d2 > measure[0] ? d2 : measure[0] + w * (d2 - measure[0]);
}

/* the noise density (rad^2 s) a measure of mean |second difference| d2 (rad) over blocks of t s gives */
static double density(double d2, double t)
{
    return (AF_PI / 2.0) / 6.0 * d2 * d2 * t;
}

/* drift_block: a block's mean field heading (unwrapped, rad) into the drift estimate; differences of
 * headings taken within [-pi, pi] (a field that turned a full circle meanwhile ends where it began). The
 * noise measure first: the |second difference| of the last three block means (a constant drift has none),
 * taken where larger than the measure (errors that come up count at once, before the block is used),
 * otherwise into its running mean, which forgets over tau_reference once that many blocks have
 * passed. White noise of density S (rad^2 s) gives block means of variance S/T_b and a mean
 * |second difference| of sqrt(6 S/T_b 2/pi): the measure's S, or r_drift where larger, is the
 * block mean's noise. Then a Kalman filter of the level (the heading at the block's middle) and
 * the drift rate: the level a random walk of the gyro's noise, the rate one of sigma_motion over
 * tau_reference; from the third block of a start on (the noise measured) past the heading's start-up
 * (start set: within it), its level set by the block before. */
static void drift_block(AfHeading *state, const AfHeadingCoef *coef, double mean, double steps, int start)
{
    double *prev = state->blk_mean, P[3] = {state->var_level, state->covariance, state->var_rate};
    double dt = 0.5 * (steps + state->blk_last) * coef->mag_delay.Ts; /* from the last block's middle to this one's */
    state->blk_last = steps;
    if (state->blocks >= 2.0)
        second_difference(state->d2, fabs(remainder(mean - 2.0 * prev[1] + prev[0], 2.0 * AF_PI)), coef->a_block);
    if (state->blocks >= 2.0 && !start) {
        double s = fmax(coef->r_drift, density(state->d2[0], coef->block_steps * coef->mag_delay.Ts));
        double r = s / (steps * coef->mag_delay.Ts);
        state->level += state->rate * dt;
        P[0] += dt * (2.0 * P[1] + dt * P[2]) + coef->q_psi * dt;
        P[1] += dt * P[2];
        P[2] += coef->q_rate * dt;
        double inv_s = 1.0 / (P[0] + r), e = remainder(mean - state->level, 2.0 * AF_PI);
        double k0 = P[0] * inv_s, k1 = P[1] * inv_s, p0 = P[0], p1 = P[1];
        state->level += k0 * e;
        state->rate += k1 * e;
        P[0] -= k0 * p0;
        P[1] -= k0 * p1;
        P[2] -= k1 * p1;
        if (fabs(state->rate) > coef->rate_max) /* no larger than the drift the parameter allows */
            state->rate = state->rate > 0.0 ? coef->rate_max : -coef->rate_max;
    } else { /* the level from this block (within the start-up, or of the first two blocks) */
        state->level = mean;
        P[0] = coef->r_drift / (steps * coef->mag_delay.Ts), P[1] = 0.0;
    }
    state->var_level = P[0], state->covariance = P[1], state->var_rate = P[2];
    state->follow = followed(state->rate, P[2], coef);
    prev[0] = prev[1], prev[1] = mean;
    state->blocks += 1.0;
}

/* field_noise: the field heading h (rad) of an accepted sample gap steps after the last: unwrapped from
 * sample to sample, into the block's mean, each block of coef->block_steps into the drift estimate */
static void field_noise(AfHeading *state, const AfHeadingCoef *coef, double h, double gap, int start)
{
    state->unwrapped += state->blk_n > 0.0 || state->blocks > 0.0 ? wrapped(h - state->h_last) : 0.0;
    state->h_last = h;
    state->blk_sum += state->unwrapped;
    state->blk_n += 1.0;
    state->blk_steps += gap;
    if (state->blk_steps < coef->block_steps)
        return;
    drift_block(state, coef, state->blk_sum / state->blk_n, state->blk_steps, start);
    state->blk_n = 0.0, state->blk_sum = 0.0, state->blk_steps = 0.0;
}

static int steady(double norm, double dip, double ref_norm, double ref_dip, double norm_tol, double dip_tol)
{
    return fabs(norm - ref_norm) <= norm_tol * ref_norm && fabs(dip - ref_dip) <= dip_tol;
}

/* new_reference: a sample outside the reference's tolerance extends the candidate field (or begins
 * one); 1 when the candidate has stayed steady for mag_new_time while the sensor turned through
 * mag_new_angle: the heading estimator then starts afresh */
static int new_reference(AfHeading *state, const AfHeadingCoef *coef, Quat q, double norm, double dip)
{
    if (state->cand_n > 0.0 && steady(norm, dip, state->cand_norm, state->cand_dip, coef->norm_tol, coef->dip_tol)) {
        state->cand_n += 1.0;
        state->cand_norm += (norm - state->cand_norm) / state->cand_n;
        state->cand_dip += (dip - state->cand_dip) / state->cand_n;
        double dot = 0.0;
        dot += q.w * state->cand_q0[0];
        dot += q.x * state->cand_q0[1];
        dot += q.y * state->cand_q0[2];
        dot += q.z * state->cand_q0[3];
        double turned = fabs(dot);
        state->cand_dot = turned < state->cand_dot ? turned : state->cand_dot;
        if (state->steps - state->cand_start + 1.0 >= coef->new_steps && state->cand_dot <= coef->cos_half_turn) {
            state->cand_n = 0.0;
            return 1;
        }
        return 0;
    }
    state->cand_norm = norm, state->cand_dip = dip, state->cand_n = 1.0, state->cand_dot = 1.0;
    state->cand_start = state->steps;
    quat_store(q, state->cand_q0);
    return 0;
}

/* noise_sample: a field sample into the noise measure: m_sensor as given (a repeat of the last is
 * a held sample, left out), m in the earth frame */
static void noise_sample(AfHeading *state, Vec3 m_sensor, Vec3 m)
{
    double *last = state->m_last;
    int held = state->noise_n > 0.0 && m_sensor.x == last[0] && m_sensor.y == last[1] && m_sensor.z == last[2];
    last[0] = m_sensor.x, last[1] = m_sensor.y, last[2] = m_sensor.z;
    if (held)
        return;
    double now[3] = {m.x, m.y, m.z};
    double(*prev)[3] = state->noise_m;
    for (int i = 0; i < 3; i++) {
        if (state->noise_n >= 2.0)
            state->noise_abs[i] += fabs(now[i] - 2.0 * prev[0][i] + prev[1][i]);
        prev[1][i] = prev[0][i], prev[0][i] = now[i];
    }
    if (state->noise_n >= 1.0)
        state->noise_span += state->noise_gap;
    state->noise_gap = 0.0;
    state->noise_n += 1.0;
}

/* guard_rate: Ts/tau of the guard's low-pass with tau_mag_guard unset, for a field of norm norm:
 * the tau that leaves white noise of s.d. sigma per sample, T steps apart (sigma^2 T Ts/(2 tau)),
 * the guard's tightest tolerance GUARD_NOISE_MARGIN s.d. wide. sigma^2: the mean over the axes of
 * (pi/2) (mean |second difference|)^2/6. Infinite (no low-pass) before a second difference. */
static double guard_rate(const AfHeading *state, const AfHeadingCoef *coef, double norm)
{
    double count = state->noise_n - 2.0;
    if (count < 1.0)
        return INFINITY;
    double mean_square = 0.0;
    for (int i = 0; i < 3; i++)
        mean_square += state->noise_abs[i] * state->noise_abs[i];
    double sigma2 = (AF_PI / 2.0) / 6.0 * mean_square / (3.0 * count * count);
    double spacing = state->noise_span / (state->noise_n - 1.0);
    double tolerance = (coef->norm_tol < coef->dip_tol ? coef->norm_tol : coef->dip_tol) * norm;
    if (!(sigma2 > 0.0 && tolerance > 0.0 && spacing > 0.0)) /* a quiet field, no tolerance, or a state */
        return INFINITY;                                     /* set from outside that says neither: as it comes */
    return 2.0 * tolerance * tolerance / (spacing * GUARD_NOISE_MARGIN * GUARD_NOISE_MARGIN * sigma2);
}

/* field_sample: the field m (earth frame before the turn by psi_c about up, which leaves its norm,
 * horizontal norm and dip alone) taken into psi_c and the reference; whether it was used. What the
 * guard judges and the heading follows is m through a low-pass (of tau_mag_guard, or unset of the
 * time guard_rate gives), which averages a fast magnetometer's noise (a field fixed in the earth
 * frame passes it unchanged); the start-up begins it at the sample, and its running mean of the heading
 * takes each sample as it comes. */
static int field_sample(AfHeading *state, const AfHeadingCoef *coef, Quat q, Vec3 m)
{
    double clip = coef->clip;
    double gap = state->gap;
    state->gap = 0.0;
    double a_low = 1.0;
    if (state->seen > 0.0 && coef->guard_online == 0.0)
        a_low = pull(gap, coef->rate_guard, coef->a_guard);
    else if (state->seen > 0.0)
        a_low = 1.0 - exp(-gap * guard_rate(state, coef, sqrt(m.x * m.x + m.y * m.y + m.z * m.z)));
    if (state->seen == 0.0)
        state->steps = 1.0;
    double *f = state->m_low;
    f[0] += a_low * (m.x - f[0]), f[1] += a_low * (m.y - f[1]), f[2] += a_low * (m.z - f[2]);
    Vec3 sample = m;
    m = (Vec3){f[0], f[1], f[2]};
    double horizontal = sqrt(m.x * m.x + m.y * m.y);
    if (horizontal == 0.0) /* a field with no heading */
        return 0;
    double norm = sqrt(horizontal * horizontal + m.z * m.z);
    double dip = atan2(-m.z, horizontal);
    state->seen += 1.0;
    int start = 1.0 / state->steps > coef->a_heading; /* within tau_heading of the start */
    int ok = 0;
    if (!start) {
        ok = steady(norm, dip, state->ref_norm, state->ref_dip, coef->norm_tol, coef->dip_tol);
        if (ok) {
            state->cand_n = 0.0;
        } else if (new_reference(state, coef, q, norm, dip)) {
            state->seen = 1.0, state->steps = 1.0, start = 1; /* a proven field: start afresh */
            restart(state, coef, 0);
        }
    }
    if (!ok && !start)
        return 0;
    double h = atan2(m.x, m.y); /* the field's heading: psi - h the heading error (psi within [-pi, pi]) */
    field_noise(state, coef, h, gap, start);
    if (start) { /* running means, every sample; psi_c's of the sample's heading, which a tilt still settling */
        ok = 1;                                   /* leaves at once (in the low-pass it lingers) */
        double h_sample = sample.x != 0.0 || sample.y != 0.0 ? atan2(sample.x, sample.y) : h;
        state->psi_c += wrapped(h_sample - state->psi_c) / state->seen;
        state->ref_norm += (norm - state->ref_norm) / state->seen;
        state->ref_dip += (dip - state->ref_dip) / state->seen;
    } else if (ok) { /* first-order pulls over the time since the last field sample */
        double error = wrapped(h - state->psi_c);
        double low = error > -clip ? error : -clip;
        state->psi_c += pull(gap, coef->rate_heading, coef->a_heading) * (low < clip ? low : clip);
        double a_reference = pull(gap, coef->rate_reference, coef->a_reference);
        state->ref_norm += a_reference * (norm - state->ref_norm);
        state->ref_dip += a_reference * (dip - state->ref_dip);
    }
    return ok;
}

/* step_turn: the rotation vector (rad, sensor frame) from q_prev to q: d = q_prev^-1 (x) q has the
 * angle 2 atan2(|v|, w) about v = (d.x, d.y, d.z); for a small step (|v| < w/10) atan(t)/t,
 * t = |v|/w, by its series (exact to double precision there) */
static Vec3 step_turn(Quat q_prev, Quat q)
{
    Quat d = quat_multiply(quat_conjugate(q_prev), q);
    if (d.w < 0.0)
        d = (Quat){-d.w, -d.x, -d.y, -d.z};
    double v2 = d.x * d.x + d.y * d.y + d.z * d.z, k;
    if (v2 < 1e-2 * d.w * d.w) {
        double inv_w = 1.0 / d.w, t2 = v2 * inv_w * inv_w;
        double t4 = t2 * t2, t8 = t4 * t4; /* the terms in pairs, the pairs in pairs (Estrin's scheme) */
        double low = (1.0 - t2 * (1.0 / 3.0)) + t4 * (1.0 / 5.0 - t2 * (1.0 / 7.0));
        double high = (1.0 / 9.0 - t2 * (1.0 / 11.0)) + t4 * (1.0 / 13.0 - t2 * (1.0 / 15.0));
        k = 2.0 * inv_w * (low + t8 * high);
    } else {
        double s = sqrt(v2);
        k = 2.0 * atan2(s, d.w) / s;
    }
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

void heading_step(AfHeading *state, const AfHeadingCoef *coef, const double q_in[4], const double m[3], double out[4],
                  int *ok)
{
    Quat q = quat_load(q_in);
    Vec3 m_sensor = {m[0], m[1], m[2]};
    state->gap += 1.0;
    state->noise_gap += 1.0;
    if (state->seen > 0.0)
        state->steps += 1.0;
    *ok = 0;
    int online = isnan(coef->delay);
    if (!online)
        state->mag_delay.delay = coef->delay;
    double Ts = coef->mag_delay.Ts;
    Quat q_prev = quat_load(state->q_prev);
    Vec3 turn = {0.0, 0.0, 0.0}; /* the last step's rotation (rad), wanted online or for a given delay */
    if ((online || coef->delay != 0.0) && fabs(q_prev.w) + fabs(q_prev.x) + fabs(q_prev.y) + fabs(q_prev.z) > 0.0)
        turn = step_turn(q_prev, q);
    if (online)
        mag_delay_turn(&state->mag_delay, &coef->mag_delay, turn);
    if (!(fabs(q_prev.w) + fabs(q_prev.x) + fabs(q_prev.y) + fabs(q_prev.z) > 0.0)) /* the first step */
        restart(state, coef, 1);
    state->psi_c += state->follow * Ts;
    double n2 = m_sensor.x * m_sensor.x + m_sensor.y * m_sensor.y + m_sensor.z * m_sensor.z;
    if (isfinite(n2) && n2 > 0.0) { /* a field sample (not NaN: missing, not all 0: none) */
        int proven = hard_iron_step(&state->hard_iron, &coef->hard_iron, m_sensor.x, m_sensor.y, m_sensor.z,
                                    state->gap, coef->norm_tol, coef->new_steps);
        m_sensor = hard_iron_removed(&state->hard_iron, &coef->hard_iron, m_sensor);
        if (proven) { /* a field freed of (or back without) an offset: start afresh from it */
            state->seen = 0.0;
            restart(state, coef, 1);
            mag_delay_restart(&state->mag_delay);
        }
        double steps = state->mag_delay.delay / Ts;
        Quat q_field = steps != 0.0 ? turned_back(q, turn, steps) : q;
        Vec3 m_earth = quat_rotate(q_field, m_sensor);
        noise_sample(state, m_sensor, m_earth);
        *ok = field_sample(state, coef, q, m_earth); /* turned by psi_c there */
        if (online) {
            Vec3 rate = {turn.x / Ts, turn.y / Ts, turn.z / Ts};
            mag_delay_field_sample(&state->mag_delay, &coef->mag_delay, m_sensor.x, m_sensor.y, m_sensor.z, rate.x,
                                   rate.y, rate.z, *ok);
        }
    }
    quat_store(q, state->q_prev);
    if (fabs(state->psi_c) > AF_PI)
        state->psi_c = atan2(sin(state->psi_c), cos(state->psi_c));
    quat_store(about_up(state->psi_c, q), out);
}

void heading_run(AfHeading *state, const AfHeadingCoef *coef, size_t n, const double *quat, const double *mag,
                 double *out, unsigned char *accepted, double *offset, double *delay)
{
    for (size_t k = 0; k < n; k++) {
        int ok;
        heading_step(state, coef, quat + 4 * k, mag + 3 * k, out + 4 * k, &ok);
        accepted[k] = (unsigned char)ok;
        for (int i = 0; i < 3; i++)
            offset[3 * k + i] = state->hard_iron.offset[i];
        delay[k] = state->mag_delay.delay;
    }
}
