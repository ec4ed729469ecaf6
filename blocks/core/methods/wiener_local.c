/* wiener_local.c: Python twin blocks/methods/wiener_local.py (run_schedule with the break
 * frequencies of the local densities); the same operations in the same order. */
#include "wiener_local.h"

#include <math.h>

#include "filters/earth_filters.h"
#include "filters/sensor_frame.h"

double band_pass_variance(double omega_m, double tau_v)
{
    double c = omega_m * tau_v;
    return c * c * (2.0 * c + 1.0) / (8.0 * tau_v * pow(c + 1.0, 2.0)); /* Python's J, operation for operation */
}

void wiener_local_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[WIENER_LOCAL_COEF_SIZE])
{
    double wm = params[AF_P_omega_m], tau_v = params[AF_P_tau_v];
    coef[0] = Ts;
    coef[1] = params[AF_P_g];
    coef[2] = pow(params[AF_P_delta_n], 2.0);
    coef[3] = 4.0 * pow(params[AF_P_scale_error], 2.0) / wm;
    coef[4] = 1.0 / band_pass_variance(wm, tau_v);
    coef[5] = pow(params[AF_P_delta_v_min], 2.0);
    coef[6] = 1.0 - exp(-Ts / params[AF_P_tau_noise]);
    coef[7] = exp(-Ts / tau_v);
}

void wiener_local_initial_state(const double coef[WIENER_LOCAL_COEF_SIZE], const double acc0[3],
                                double state[WIENER_LOCAL_STATE_SIZE])
{
    double norm = sqrt(acc0[0] * acc0[0] + acc0[1] * acc0[1] + acc0[2] * acc0[2]);
    int i;
    for (i = 0; i < WIENER_LOCAL_STATE_SIZE; i++) state[i] = 0.0;
    for (i = 0; i < 3; i++) {
        state[i] = norm > 0.0 ? acc0[i] * (coef[1] / norm) : (i == 2 ? coef[1] : 0.0);
        state[9 + i] = acc0[i];
    }
    state[WIENER_LOCAL_QUAT] = 1.0;
}

void butterworth_zoh(double wt, double Ad[4], double Bd[2])
{
    /* M has eigenvalues (-1 +- i)/sqrt 2: exp(M t) = e^(-t/sqrt 2) (cos(t/sqrt 2) I + sqrt 2 sin(t/sqrt 2) (M + I/sqrt 2)) */
    double a = wt / SQRT2;
    double e = exp(-a);
    double c = e * cos(a), s = e * sin(a) * SQRT2;
    Ad[0] = c + s / SQRT2;
    Ad[1] = s;
    Ad[2] = -s;
    Ad[3] = c - s / SQRT2;
    /* M^-1 = [[-sqrt 2, -1], [1, 0]] applied to (Ad - I)[:, 1] */
    Bd[0] = -SQRT2 * Ad[1] - (Ad[3] - 1.0);
    Bd[1] = Ad[1];
}

double local_omega_g(double state[WIENER_LOCAL_STATE_SIZE], const double coef[WIENER_LOCAL_COEF_SIZE],
                     const double gyr[3], const double acc[3], double turned[12])
{
    double Ts = coef[0], g = coef[1], dn2 = coef[2], k_w = coef[3], inv_J = coef[4], dv2_min = coef[5];
    double a_avg = coef[6], leak = coef[7], v2 = 0.0, w2, slosh;
    int i;
    for (i = 0; i < 3; i++) {
        turned[9 + i] += (1.0 - leak) * (acc[i] - turned[9 + i]);
        turned[6 + i] = leak * turned[6 + i] + Ts * (acc[i] - turned[9 + i]);
        v2 += turned[6 + i] * turned[6 + i];
    }
    w2 = gyr[0] * gyr[0] + gyr[1] * gyr[1] + gyr[2] * gyr[2];
    state[WIENER_LOCAL_W2] += a_avg * (w2 - state[WIENER_LOCAL_W2]);
    state[WIENER_LOCAL_V2] += a_avg * (v2 / 3.0 - state[WIENER_LOCAL_V2]);
    slosh = inv_J * state[WIENER_LOCAL_V2];
    return sqrt(g * sqrt((dn2 + k_w * state[WIENER_LOCAL_W2]) / (dv2_min > slosh ? dv2_min : slosh))); /* eq. 25 */
}

void wiener_local_run(double state[WIENER_LOCAL_STATE_SIZE], const double coef[WIENER_LOCAL_COEF_SIZE],
                      const double gyr[3], const double acc[3], double gravity[3], double quat[4])
{
    static const double C[2] = {1.0, 0.0};
    double Ts = coef[0], turned[12], Ad[4], Bd[2], omega;
    double *rows = state + WIENER_LOCAL_ROWS, *q = state + WIENER_LOCAL_QUAT;
    Quat dq = turn_rows(rows, turned, 4, gyr, Ts);
    int i;
    omega = local_omega_g(state, coef, gyr, acc, turned);
    if (state[WIENER_LOCAL_OMEGA] > 0.0) /* keep e = u/omega_g continuous across a change of omega_g */
        for (i = 0; i < 3; i++) turned[3 + i] *= omega / state[WIENER_LOCAL_OMEGA];
    state[WIENER_LOCAL_OMEGA] = omega;
    state[WIENER_LOCAL_T] += Ts;
    if (state[WIENER_LOCAL_T] * omega < SQRT2) {
        /* start-up, within the filter's time constant sqrt 2/omega_g: the mean of the
         * accelerometer so far in the gyro frame (no state velocity) */
        double n = state[WIENER_LOCAL_T] / Ts;
        for (i = 0; i < 3; i++) {
            rows[i] = turned[i] + (acc[i] - turned[i]) / n;
            rows[3 + i] = 0.0;
            gravity[i] = rows[i];
        }
    } else {
        butterworth_zoh(omega * Ts, Ad, Bd);
        filter_rows(rows, turned, acc, 2, Ad, Bd, C, 0.0, gravity);
    }
    for (i = 0; i < 3; i++) {
        rows[6 + i] = turned[6 + i];
        rows[9 + i] = turned[9 + i];
    }
    level_onto_gravity(q, dq, gravity);
    for (i = 0; i < 4; i++) quat[i] = q[i];
}
