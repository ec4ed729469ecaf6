/* luinge.h: Luinge's tilt Kalman filter (Luinge, Veltink, Baten; Fig. 1 of the seed paper):
 * the gyro's orientation corrected by a 2-state Kalman filter on the tilt difference to the
 * accelerometer's up. Python twin: blocks/methods/luinge.py (state and coefficients in its layout). */
#ifndef AF_LUINGE_H
#define AF_LUINGE_H

#include "af_params.h"
#include "quaternion.h"

#define LUINGE_STATE_SIZE 6 /* q_w, q_x, q_y, q_z (sensor -> earth), P_x, P_y (tilt variances, rad^2) */
#define LUINGE_COEF_SIZE 4  /* [Q (rad^2 per sample), R = tilt_sd^2 (rad^2), Ts (s), g (m/s^2)] */

void luinge_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[LUINGE_COEF_SIZE]);

/* Level on acc0 (heading 0), tilt variance R (the accelerometer's own). */
void luinge_initial_state(const double coef[LUINGE_COEF_SIZE], const double acc0[3], double state[LUINGE_STATE_SIZE]);

/* One sample on state [q, P_x, P_y] in place; returns the unit up estimate. */
Vec3 luinge_step(double state[LUINGE_STATE_SIZE], double Q, double R, double Ts, const double gyr[3],
                 const double acc[3]);

/* run on one sample: writes the gravity estimate (g up, m/s^2) and q. */
void luinge_run(double state[LUINGE_STATE_SIZE], const double coef[LUINGE_COEF_SIZE], const double gyr[3],
                const double acc[3], double gravity[3], double quat[4]);

#endif
