/* mahony.h: Mahony's complementary filter on SO(3) with gyro-bias estimation (Mahony, Hamel,
 * Pflimlin 2008, IEEE TAC 53), the explicit form for the gravity direction.
 * Python twin: blocks/methods/mahony.py (state [q, b] and coefficients in its layout). */
#ifndef AF_MAHONY_H
#define AF_MAHONY_H

#include "af_params.h"
#include "quaternion.h"

#define MAHONY_STATE_SIZE 7 /* q_w, q_x, q_y, q_z, b_x, b_y, b_z: q sensor -> earth, gyro bias (rad/s) */
#define MAHONY_COEF_SIZE 4  /* [k_P (1/s), k_I (1/s^2), Ts (s), g (m/s^2)] */

#include <stddef.h>

/* check_gains: 0, or -1 with Python's message for gains k_P (1/s) and k_I (1/s^2) with which
 * the step diverges at the sample time Ts (s): k_P Ts < 2 and k_I Ts^2 < 4 - 2 k_P Ts hold
 * where the linearised step's poles lie inside the unit circle. */
int mahony_check_gains(double k_P, double k_I, double Ts, char *message, size_t size);

/* coefficients(params, Ts): 0, or -1 with check_gains's message. */
int mahony_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[MAHONY_COEF_SIZE], char *message,
                        size_t size);

/* Level on acc0 (heading 0), no bias. */
void mahony_initial_state(const double coef[MAHONY_COEF_SIZE], const double acc0[3], double state[MAHONY_STATE_SIZE]);

/* The quaternion (sensor -> earth) of the smallest rotation taking acc0 onto up, into q. */
void level_on(const double acc0[3], double q[4]);

/* One sample of the filter on state [q, b] in place; returns the unit up estimate. */
Vec3 mahony_step(double state[MAHONY_STATE_SIZE], double k_P, double k_I, double Ts, const double gyr[3],
                 const double acc[3]);

/* run on one sample: writes the gravity estimate (g up, m/s^2) and q. */
void mahony_run(double state[MAHONY_STATE_SIZE], const double coef[MAHONY_COEF_SIZE], const double gyr[3],
                const double acc[3], double gravity[3], double quat[4]);

#endif
