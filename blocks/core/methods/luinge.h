/* luinge.h: Luinge's tilt Kalman filter (Luinge, Veltink, Baten; Fig. 1 of the seed paper).
 *
 * (1) integrate the gyro to an orientation q; (2) the accelerometer's up-vector; (3) the tilt
 * difference between the two, split from the rotation alpha about the vertical; (5) a linear
 * 2-state Kalman filter on that difference with prediction dT = 0; (4) rebuild the orientation
 * from the corrected tilt and the unchanged alpha.
 *
 * The paper writes tilt as T = (acos Z_s,x, acos Z_s,y), which degenerates when a sensor axis
 * is vertical. Here the tilt difference is the horizontal earth-frame rotation vector taking the
 * measured up (seen through q) onto earth up: equal to first order, free of singularities, and
 * its correction (a rotation about a horizontal axis) leaves alpha alone. Per axis: P- = P + Q
 * with Q = dn^2/2 Ts (eq. 10 of Rizun), K = P-/(P- + sigma_T^2), P = (1 - K) P-. */
#ifndef AF_LUINGE_H
#define AF_LUINGE_H

#include "af_params.h"
#include "quaternion.h"

/* The state: the orientation and the Kalman filter's tilt variances. */
typedef struct {
    Quat q;      /* sensor -> earth */
    double P[2]; /* tilt variances about earth x and y, rad^2 */
} LuingeState;

typedef struct {
    double Q;  /* process noise per sample, rad^2: delta_n^2/2 Ts */
    double R;  /* the accelerometer tilt's variance, tilt_sd^2, rad^2 */
    double Ts; /* s */
    double g;  /* m/s^2, the gravity output's magnitude */
} LuingeCoef;

void luinge_coefficients(const double params[AF_N_PARAMS], double Ts, LuingeCoef *coef);

/* Level on acc0 (heading 0), tilt variance R (the accelerometer's own). */
void luinge_initial_state(const LuingeCoef *coef, const double acc0[3], LuingeState *state);

/* One sample on the state in place; returns the unit up estimate. */
Vec3 luinge_step(LuingeState *state, double Q, double R, double Ts, const double gyr[3], const double acc[3]);

/* run on one sample: writes the gravity estimate (g up, m/s^2) and q. */
void luinge_run(LuingeState *state, const LuingeCoef *coef, const double gyr[3], const double acc[3],
                double gravity[3], double quat[4]);

#endif
