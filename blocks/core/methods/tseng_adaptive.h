/* tseng_adaptive.h: Tseng's adaptive complementary filter: the complementary filter (the
 * `tseng` earth filter in the sensor frame) while the accelerometer norm stays within tol of
 * g, Mahony's filter while it does not; leaving Mahony's filter, the complementary filter
 * restarts at rest on its estimate. Python twin: blocks/methods/tseng_adaptive.py
 * (state [X (3 n), q, b] and coefficients [n, Ts, tol, g, k_P, k_I, D, Ad (n^2), Bd (n), C (n),
 * x_rest (n)] in its layout). */
#ifndef AF_TSENG_ADAPTIVE_H
#define AF_TSENG_ADAPTIVE_H

#include <stddef.h>

#include "af_params.h"
#include "filters/tseng.h"

#define TSENG_ADAPTIVE_STATE_SIZE (3 * TSENG_ORDER + 7)
#define TSENG_ADAPTIVE_COEF_SIZE (7 + TSENG_ORDER * TSENG_ORDER + 3 * TSENG_ORDER)

/* coefficients(params, Ts): the tseng filter held over Ts (s). 0, or -1 with the message of
 * Mahony gains that diverge at Ts (mahony_check_gains, for its Mahony mode) or of a Ts that is
 * not finite and positive. */
int tseng_adaptive_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[TSENG_ADAPTIVE_COEF_SIZE],
                                char *message, size_t size);

/* At rest on acc0 (m/s^2), q the identity, no bias. */
void tseng_adaptive_initial_state(const double coef[TSENG_ADAPTIVE_COEF_SIZE], const double acc0[3],
                                  double state[TSENG_ADAPTIVE_STATE_SIZE]);

/* run on one sample: writes the gravity estimate (m/s^2) and q. */
void tseng_adaptive_run(double state[TSENG_ADAPTIVE_STATE_SIZE], const double coef[TSENG_ADAPTIVE_COEF_SIZE],
                        const double gyr[3], const double acc[3], double gravity[3], double quat[4]);

#endif
