/* mag_delay.h: online estimate of the magnetometer's delay behind the gyro.
 * Python twin: blocks/stages/mag_delay.py. */
#ifndef AF_MAG_DELAY_H
#define AF_MAG_DELAY_H

#include "af_params.h"
#include "quaternion.h"

#define MAG_SPAN_S 0.25       /* s: the field is compared with the gyro over about this long */
#define MAG_DELAY_REACH_S 0.1 /* s: the largest delay looked for */
#define MAG_DELAY_SIGMAS 3.0  /* a delay is taken only this many standard errors or more from 0 */
#define MAG_DELAY_MIN_S 5.0   /* s of accepted field samples in the sums before a delay is taken */
#define MAG_DELAY_STATE_SIZE 22 /* STATE_SIZE */
#define MAG_DELAY_COEF_SIZE 6   /* COEF_SIZE */
#define MAG_DELAY_STATE_DELAY 21 /* DELAY: the delay in use (s) */

/* coefficients: [Ts (s), 1/MAG_SPAN_S, 1/tau_mag_delay, MAG_DELAY_SIGMAS, MAG_DELAY_REACH_S, MAG_DELAY_MIN_S]. */
void mag_delay_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[MAG_DELAY_COEF_SIZE]);

/* turn: every step, the step's rotation (rad) added to the integrated rate. */
void mag_delay_turn(double state[MAG_DELAY_STATE_SIZE], const double coef[MAG_DELAY_COEF_SIZE], Vec3 rotation);

/* restart: every sample forgotten, the delay in use reset to 0 (a hard-iron offset taken or dropped). */
void mag_delay_restart(double state[MAG_DELAY_STATE_SIZE]);

/* field_sample: a field sample m (sensor frame, hard iron removed) with the step's rate w (rad/s);
 * the interval since the last one enters the estimate when use (the guard accepted it). */
void mag_delay_field_sample(double state[MAG_DELAY_STATE_SIZE], const double coef[MAG_DELAY_COEF_SIZE], Vec3 m, Vec3 w,
                            int use);

#endif
