/* sensor_frame.h: the sensor-frame transformation (Rizun eq. 35) of an earth-frame LTI
 * filter, in discrete time: each of the filter's n states is a 3-vector (a row of X, n x 3,
 * row-major) that turns with the gyro by the exact rotation of each sample, and the LTI
 * part is its zero-order hold (Ad, Bd) at the sample time Ts.
 * Python twin: blocks/filters/sensor_frame.py (same names; its numpy rows are pointers
 * here, its tuples Quat and Vec3). Units: gyr rad/s (the mean rate over the sample),
 * acc and the gravity estimate m/s^2, Ts s; q is sensor -> earth, [w, x, y, z]. */
#ifndef AF_SENSOR_FRAME_H
#define AF_SENSOR_FRAME_H

#include <stddef.h>

#include "filters/earth_filters.h"
#include "quaternion.h"

/* The zero-order-hold form of an earth filter at sample time Ts (s). */
typedef struct {
    int n;
    double Ad[MAX_ORDER * MAX_ORDER]; /* n x n, row-major */
    double Bd[MAX_ORDER];
    double C[MAX_ORDER];
    double D;
    double Ts;
} DiscreteFilter;

#define SENSOR_FRAME_STATE_SIZE(n) (3 * (n) + 4) /* the stepper's state: X row by row, then q */

/* DiscreteFilter.from_lti: f held over Ts, exp([[A, B], [0, 0]] Ts) as control.c2d(.., "zoh")
 * computes it, for any Ts. 0, or -1 with the message of a Ts that is not finite and positive. */
int discrete_filter(const EarthFilter *f, double Ts, DiscreteFilter *out, char *message, size_t size);

/* The state X (n x 3) the filter holds after resting on the constant input acc0 (m/s^2):
 * (I - Ad)^-1 Bd acc0^T. */
void rest_state(const DiscreteFilter *d, const double acc0[3], double *X);

/* The n rows of X (earth-fixed vectors in sensor coordinates) turned into this sample's
 * sensor frame, written to Xr: the exact rotation by -gyr Ts. Returns the sample's rotation
 * quaternion exp(gyr Ts). */
Quat turn_rows(const double *X, double *Xr, int n, const double gyr[3], double Ts);

/* The discrete LTI filter per axis: X = Ad Xr + Bd acc^T, g_out = C X + D acc (n states;
 * Ad n x n row-major). */
void filter_rows(double *X, const double *Xr, const double acc[3], int n, const double *Ad, const double *Bd,
                 const double *C, double D, double g_out[3]);

/* q (in place, sensor -> earth): the sample's rotation dq integrated, then levelled so that
 * q turns the gravity estimate g onto earth up (heading stays the integrated gyro's). */
void level_onto_gravity(double q[4], Quat dq, const double g[3]);

/* One sample: the rows of X (n x 3) turned by -gyr Ts, the zero-order-hold filter applied to
 * acc, the gravity estimate written to g_out and q levelled onto it; X and q in place. */
void sensor_frame_step(double *X, double q[4], const double gyr[3], const double acc[3], int n, const double *Ad,
                       const double *Bd, const double *C, double D, double Ts, double g_out[3]);

/* The gravity to start at rest on before the first sample: acc0 (m/s^2, at the end of the
 * first interval) turned back by that interval's rotation gyr0 Ts. */
void start_gravity(const double gyr0[3], const double acc0[3], double Ts, double out[3]);

/* SensorFrameStepper.initial_state: at rest on acc0 (m/s^2), q the identity;
 * SENSOR_FRAME_STATE_SIZE(d->n) values. */
void sensor_frame_initial_state(const DiscreteFilter *d, const double acc0[3], double *state);

#endif
