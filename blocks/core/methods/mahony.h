/* mahony.h: Mahony's complementary filter on SO(3) with gyro-bias estimation (Mahony, Hamel,
 * Pflimlin 2008, IEEE TAC 53), the explicit form for the gravity direction:
 *
 *     e = v x v^,  w_c = w_y - b^ + k_P e,  db^/dt = -k_I e,  dq/dt = 1/2 q (x) w_c,
 *
 * with v the measured up (accelerometer) and v^ = R(q)^T z the estimated up, both unit vectors
 * in sensor coordinates. Discrete time: w_c held over the sample, integrated as an exact
 * rotation. */
#ifndef AF_MAHONY_H
#define AF_MAHONY_H

#include <stddef.h>

#include "af_params.h"
#include "quaternion.h"

/* The state: the orientation and the gyro-bias estimate. */
typedef struct {
    Quat q; /* sensor -> earth */
    Vec3 b; /* gyro bias, rad/s */
} MahonyState;

typedef struct {
    double k_P; /* 1/s */
    double k_I; /* 1/s^2 */
    double Ts;  /* s */
    double g;   /* m/s^2, the gravity output's magnitude */
} MahonyCoef;

/* check_gains: 0, or -1 with a message for gains k_P (1/s) and k_I (1/s^2) with which the step
 * diverges at the sample time Ts (s). Linearised about the true attitude (tilt error x, bias
 * error beta, both per axis), a step is beta' = beta + k_I Ts x, x' = (1 - k_P Ts) x - Ts beta',
 * whose poles lie inside the unit circle (Jury) for k_P Ts < 2 and k_I Ts^2 < 4 - 2 k_P Ts. */
int mahony_check_gains(double k_P, double k_I, double Ts, char *message, size_t size);

/* coefficients(params, Ts): 0, or -1 with check_gains's message. */
int mahony_coefficients(const double params[AF_N_PARAMS], double Ts, MahonyCoef *coef, char *message, size_t size);

/* Level on acc0 (heading 0), no bias. */
void mahony_initial_state(const MahonyCoef *coef, const double acc0[3], MahonyState *state);

/* The quaternion (sensor -> earth) of the smallest rotation taking acc0 onto up; the identity where acc0
 * is 0 (free fall, or python-control's first pass over a diagram: nothing to level on). */
Quat level_on(const double acc0[3]);

/* One sample of the filter on state in place; returns the unit up estimate. */
Vec3 mahony_step(MahonyState *state, double k_P, double k_I, double Ts, const double gyr[3], const double acc[3]);

/* run on one sample: writes the gravity estimate (g up, m/s^2) and q. */
void mahony_run(MahonyState *state, const MahonyCoef *coef, const double gyr[3], const double acc[3],
                double gravity[3], double quat[4]);

#endif
