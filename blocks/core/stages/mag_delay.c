/* mag_delay.c: Python twin blocks/stages/mag_delay.py; the same operations in the same order. */
#include "stages/mag_delay.h"

#include <math.h>

/* the state's layout (STATE_NAMES) */
#define LAST_M 0  /* the last field sample (sensor frame, hard iron removed), 3 entries */
#define LAST_W 3  /* the rate at it (rad/s), 3 */
#define TURN 6    /* the integrated rate since it (rad), 3 */
#define SINCE 9   /* time since it (s) */
#define SEEN 10   /* 1 once there was one */
#define Y 11      /* L[dm/dt + w x m], 3 */
#define J 14      /* L[dw/dt x m], 3 */
#define SUMS 17   /* sum y.J.dt, |J|^2.dt, |y|^2.dt, dt (forgotten over tau_mag_delay) */
#define DELAY MAG_DELAY_STATE_DELAY /* the delay in use (s) */

void mag_delay_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[MAG_DELAY_COEF_SIZE])
{
    coef[0] = Ts;
    coef[1] = 1.0 / MAG_SPAN_S;
    coef[2] = 1.0 / params[AF_P_tau_mag_delay];
    coef[3] = MAG_DELAY_SIGMAS;
    coef[4] = MAG_DELAY_REACH_S;
    coef[5] = MAG_DELAY_MIN_S;
}

void mag_delay_turn(double state[MAG_DELAY_STATE_SIZE], const double coef[MAG_DELAY_COEF_SIZE], Vec3 rotation)
{
    state[TURN] += rotation.x;
    state[TURN + 1] += rotation.y;
    state[TURN + 2] += rotation.z;
    state[SINCE] += coef[0];
}

void mag_delay_restart(double state[MAG_DELAY_STATE_SIZE])
{
    for (int i = 0; i < MAG_DELAY_STATE_SIZE; i++)
        state[i] = 0.0;
}

static Vec3 cross(Vec3 a, Vec3 b)
{
    return (Vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

void mag_delay_field_sample(double state[MAG_DELAY_STATE_SIZE], const double coef[MAG_DELAY_COEF_SIZE], Vec3 m, Vec3 w,
                            int use)
{
    double dt = state[SINCE];
    double *last_m = state + LAST_M, *last_w = state + LAST_W, *turned = state + TURN;
    double *y_lp = state + Y, *j_lp = state + J, *sums = state + SUMS;
    if (state[SEEN] > 0.0 && dt > 0.0) {
        double a = coef[1], lag = exp(-coef[1] * dt);
        Vec3 mid = {0.5 * (m.x + last_m[0]), 0.5 * (m.y + last_m[1]), 0.5 * (m.z + last_m[2])};
        Vec3 carried = cross((Vec3){turned[0], turned[1], turned[2]}, mid); /* integral of w x m */
        Vec3 j = cross((Vec3){w.x - last_w[0], w.y - last_w[1], w.z - last_w[2]}, mid); /* integral of dw/dt x m */
        double dm[3] = {m.x - last_m[0] + carried.x, m.y - last_m[1] + carried.y, m.z - last_m[2] + carried.z};
        double jv[3] = {j.x, j.y, j.z};
        for (int i = 0; i < 3; i++) { /* the low-passes, their input constant over the interval */
            y_lp[i] = lag * y_lp[i] + (1.0 - lag) * dm[i] / dt;
            j_lp[i] = lag * j_lp[i] + (1.0 - lag) * jv[i] / dt;
        }
        if (use) {
            double forget = exp(-coef[2] * dt);
            double terms[4] = {y_lp[0] * j_lp[0] + y_lp[1] * j_lp[1] + y_lp[2] * j_lp[2],
                               j_lp[0] * j_lp[0] + j_lp[1] * j_lp[1] + j_lp[2] * j_lp[2],
                               y_lp[0] * y_lp[0] + y_lp[1] * y_lp[1] + y_lp[2] * y_lp[2], 1.0};
            for (int i = 0; i < 4; i++)
                sums[i] = forget * sums[i] + terms[i] * dt;
            if (sums[1] > 0.0 && sums[3] >= coef[5]) {
                double d = sums[0] / sums[1];
                double excess = sums[2] - d * sums[0];
                double residual = (0.0 > excess ? 0.0 : excess) / sums[3]; /* <|y - d.J|^2> */
                /* |d| >= k.SE with SE^2 = (2/a).(residual/3)/sum |J|^2.dt */
                if (d * d * sums[1] * 3.0 * a >= coef[3] * coef[3] * 2.0 * residual) {
                    double low = 0.0 > d ? 0.0 : d;
                    state[DELAY] = coef[4] < low ? coef[4] : low;
                }
            }
        }
    }
    last_m[0] = m.x, last_m[1] = m.y, last_m[2] = m.z;
    last_w[0] = w.x, last_w[1] = w.y, last_w[2] = w.z;
    turned[0] = turned[1] = turned[2] = 0.0;
    state[SINCE] = 0.0, state[SEEN] = 1.0;
}
