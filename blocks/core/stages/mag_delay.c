/* mag_delay.c: the online estimate of the magnetometer's delay (documented in blocks/stages/mag_delay.py). */
#include "stages/mag_delay.h"

#include <math.h>
#include <string.h>

#define STATE_FIELD(name, dims) AF_FIELD(AfMagDelay, name)
const AfField MAG_DELAY_STATE_FIELDS[] = {MAG_DELAY_FIELDS(STATE_FIELD)};
const size_t MAG_DELAY_N_FIELDS = sizeof MAG_DELAY_STATE_FIELDS / sizeof MAG_DELAY_STATE_FIELDS[0];

void mag_delay_coefficients(const double params[AF_N_PARAMS], double Ts, AfMagDelayCoef *coef)
{
    coef->Ts = Ts;
    coef->a = 1.0 / MAG_SPAN_S;
    coef->rate = 1.0 / params[AF_P_tau_mag_delay];
    coef->lag = exp(-coef->a * Ts);
    coef->forget = exp(-coef->rate * Ts);
    coef->weight = (1.0 - coef->lag) / Ts;
}

void mag_delay_restart(AfMagDelay *state)
{
    memset(state, 0, sizeof *state);
}

static Vec3 cross(Vec3 a, Vec3 b)
{
    return (Vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

void mag_delay_field_sample(AfMagDelay *state, const AfMagDelayCoef *coef, double mx, double my, double mz, double wx,
                            double wy, double wz, int use)
{
    Vec3 m = {mx, my, mz}, w = {wx, wy, wz};
    double dt = state->since, *sums = state->sums;
    if (state->seen > 0.0 && dt > 0.0) {
        double a = coef->a, one_step = dt == coef->Ts;
        double lag = one_step ? coef->lag : exp(-a * dt);
        double weight = one_step ? coef->weight : (1.0 - lag) / dt; /* of the input's rate of change */
        const double *last_m = state->last_m, *last_w = state->last_w;
        Vec3 mid = {0.5 * (m.x + last_m[0]), 0.5 * (m.y + last_m[1]), 0.5 * (m.z + last_m[2])};
        Vec3 carried = cross((Vec3){state->turn[0], state->turn[1], state->turn[2]}, mid); /* integral of w x m */
        Vec3 j = cross((Vec3){w.x - last_w[0], w.y - last_w[1], w.z - last_w[2]}, mid); /* integral of dw/dt x m */
        double dm[3] = {m.x - last_m[0] + carried.x, m.y - last_m[1] + carried.y, m.z - last_m[2] + carried.z};
        double jv[3] = {j.x, j.y, j.z};
        double *y_lp = state->y, *j_lp = state->j;
        for (int i = 0; i < 3; i++) { /* the low-passes, their input constant over the interval */
            y_lp[i] = lag * y_lp[i] + weight * dm[i];
            j_lp[i] = lag * j_lp[i] + weight * jv[i];
        }
        state->clean = use ? state->clean + dt : 0.0;
        if (use && state->clean >= MAG_DELAY_CLEAN_S) {
            double forget = one_step ? coef->forget : exp(-coef->rate * dt);
            /* term by term (an array of the terms goes through the stack: stored one at a time, read two at a time) */
            sums[0] = forget * sums[0] + (y_lp[0] * j_lp[0] + y_lp[1] * j_lp[1] + y_lp[2] * j_lp[2]) * dt;
            sums[1] = forget * sums[1] + (j_lp[0] * j_lp[0] + j_lp[1] * j_lp[1] + j_lp[2] * j_lp[2]) * dt;
            sums[2] = forget * sums[2] + (y_lp[0] * y_lp[0] + y_lp[1] * y_lp[1] + y_lp[2] * y_lp[2]) * dt;
            sums[3] = forget * sums[3] + 1.0 * dt;
            if (sums[1] > 0.0 && sums[3] >= MAG_DELAY_MIN_S) {
                /* d = s_yj/s_jj, the mean square residual <|y - d.j|^2> = (s_yy - d.s_yj)/s_t; |d| >= k.SE with
                 * SE^2 = (2/a).(residual/3)/s_jj, both sides times s_jj.s_t (> 0) */
                double excess = sums[2] * sums[1] - sums[0] * sums[0]; /* (s_yy - d.s_yj).s_jj */
                if (sums[0] * sums[0] * sums[3] * 3.0 * a >=
                    MAG_DELAY_SIGMAS * MAG_DELAY_SIGMAS * 2.0 * (0.0 > excess ? 0.0 : excess)) {
                    double d = sums[0] / sums[1];
                    double low = 0.0 > d ? 0.0 : d;
                    state->delay = MAG_DELAY_REACH_S < low ? MAG_DELAY_REACH_S : low;
                }
            }
        }
    }
    state->last_m[0] = m.x, state->last_m[1] = m.y, state->last_m[2] = m.z;
    state->last_w[0] = w.x, state->last_w[1] = w.y, state->last_w[2] = w.z;
    state->turn[0] = state->turn[1] = state->turn[2] = 0.0;
    state->since = 0.0, state->seen = 1.0;
}
