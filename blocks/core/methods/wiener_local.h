/* wiener_local.h: Rizun's Wiener filter with its noise densities estimated locally (the
 * default `wiener`): eq. 34 in the sensor frame, omega_g re-derived every sample from the
 * gyro's and the slosh's densities over the last tau_noise seconds.
 * Python twin: blocks/methods/wiener_local.py (state and coefficients in its layout). */
#ifndef AF_WIENER_LOCAL_H
#define AF_WIENER_LOCAL_H

#include "af_params.h"

/* the state, as STATE_NAMES: g (m/s^2), u = omega_g e (m/s^2), v (m/s), f (m/s^2), rows of 3
 * that turn with the gyro; q (sensor -> earth); <|w|^2> (rad^2/s^2), <|v|^2>/3 (m^2/s^2),
 * the last omega_g (rad/s), the time since the start (s) */
#define WIENER_LOCAL_STATE_SIZE 20
#define WIENER_LOCAL_ROWS 0 /* 4 rows of 3 from here */
#define WIENER_LOCAL_QUAT 12
#define WIENER_LOCAL_W2 16
#define WIENER_LOCAL_V2 17
#define WIENER_LOCAL_OMEGA 18
#define WIENER_LOCAL_T 19
#define WIENER_LOCAL_COEF_SIZE 8 /* [Ts, g, dn^2, k_w, 1/J, dv_min^2, a_avg, leak_v] */

/* J, the variance per unit density that the band-pass of time constant tau_v (s) leaves of
 * eq. 14's velocity band-limited at omega_m (rad/s): (1/2 pi) int (w tau_v)^4 / (1 + w^2
 * tau_v^2)^2 / (1 + w^2/omega_m^2) dw, in closed form c^2 (2c + 1) / (8 tau_v (1 + c)^2),
 * c = omega_m tau_v, the formula of Python's coefficients. */
double band_pass_variance(double omega_m, double tau_v);

/* coefficients(params, Ts): params the method's resolved values (AF_P_<name>), Ts s. */
void wiener_local_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[WIENER_LOCAL_COEF_SIZE]);

/* At rest on acc0 (m/s^2): g along acc0 with the magnitude coef[1], q the identity. */
void wiener_local_initial_state(const double coef[WIENER_LOCAL_COEF_SIZE], const double acc0[3],
                                double state[WIENER_LOCAL_STATE_SIZE]);

/* Ad = exp(M wt), Bd = M^-1 (Ad - I) [0, 1] of the realisation M = [[0, 1], [-1, -sqrt 2]] for
 * wt = omega_g Ts (rad), in closed form; Ad 2 x 2 row-major. */
void butterworth_zoh(double wt, double Ad[4], double Bd[2]);

/* The running densities updated with a sample (turned: the 4 state rows in this sample's
 * frame, whose rows 2 and 3 are updated here); returns omega_g (rad/s). */
double local_omega_g(double state[WIENER_LOCAL_STATE_SIZE], const double coef[WIENER_LOCAL_COEF_SIZE],
                     const double gyr[3], const double acc[3], double turned[12]);

/* One sample (run on one row): gyr (rad/s, mean over the sample), acc (m/s^2); writes the
 * gravity estimate (m/s^2) and q. */
void wiener_local_run(double state[WIENER_LOCAL_STATE_SIZE], const double coef[WIENER_LOCAL_COEF_SIZE],
                      const double gyr[3], const double acc[3], double gravity[3], double quat[4]);

#endif
