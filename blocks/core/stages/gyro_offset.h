/* gyro_offset.h: the gyroscope-offset estimator (rest detection, the Kalman filter at rest,
 * the tracking while moving). Python twin: blocks/stages/gyro_offset.py. */
#ifndef AF_GYRO_OFFSET_H
#define AF_GYRO_OFFSET_H

#include "af_params.h"

#define GYRO_OFFSET_STATE_SIZE 60 /* len(STATE_NAMES) */
#define GYRO_OFFSET_COEF_SIZE 12  /* see gyro_offset_coefficients */
#define REST_NOISE_SIGMAS 4.5     /* the least rest_gyr in units of the gyro noise's per-axis s.d. through tau_short */

/* coefficients: [Ts, a_lp, r, rest_gyr, rest_gyr_abs, rest_acc, rest_time, w_acc*Ts, P0, V, W, a_short]
 * from the stage's resolved parameters (AF_P_<name>) at Ts (s). */
void gyro_offset_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[GYRO_OFFSET_COEF_SIZE]);

/* initial_state: low-passes on the first samples gyr0 (rad/s), acc0 (m/s^2), no offset. */
void gyro_offset_initial_state(const double coef[GYRO_OFFSET_COEF_SIZE], const double gyr0[3], const double acc0[3],
                               double state[GYRO_OFFSET_STATE_SIZE]);

/* One sample of run (gyr rad/s, acc m/s^2): state in place; the offset estimate after it
 * (rad/s) and its variance per axis ((rad/s)^2). */
void gyro_offset_step(double state[GYRO_OFFSET_STATE_SIZE], const double coef[GYRO_OFFSET_COEF_SIZE],
                      const double gyr[3], const double acc[3], double offset[3], double variance[3]);

#endif
