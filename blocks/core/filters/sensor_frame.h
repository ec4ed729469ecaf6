/* sensor_frame.h: the sensor-frame transformation (Rizun eq. 35) of an earth-frame LTI
 * filter, in discrete time: each of the filter's n states is a 3-vector (a row of X, n x 3,
 * row-major) that turns with the gyro by the exact rotation of each sample, and the LTI
 * part is its zero-order hold (Ad, Bd) at the sample time Ts.
 * blocks/filters/sensor_frame.py designs the filters and binds the step. Units: gyr rad/s
 * (the mean rate over the sample), acc and the gravity estimate m/s^2, Ts s; q is
 * sensor -> earth, [w, x, y, z]. */
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

/* Vec3 and Quat are rows of doubles: a state array of doubles holds them */
typedef char vec3_is_three_doubles[sizeof(Vec3) == 3 * sizeof(double) ? 1 : -1];
typedef char quat_is_four_doubles[sizeof(Quat) == 4 * sizeof(double) ? 1 : -1];

/* DiscreteFilter.from_lti: f held over Ts, exp([[A, B], [0, 0]] Ts) as control.c2d(.., "zoh")
 * computes it, for any Ts. 0, or -1 with the message of a Ts that is not finite and positive. */
int discrete_filter(const EarthFilter *f, double Ts, DiscreteFilter *out, char *message, size_t size);

/* The state X (n x 3) the filter holds after resting on the constant input acc0 (m/s^2):
 * (I - Ad)^-1 Bd acc0^T. */
void rest_state(const DiscreteFilter *d, const double acc0[3], double *X);

/* q (sensor -> earth) after the sample's rotation dq, levelled so that it turns the gravity
 * estimate g onto earth up (its heading stays the integrated gyro's); normalised. */
static inline Quat level_onto_gravity(Quat q, Quat dq, Vec3 g)
{
    Quat turned = quat_multiply(q, dq);
    double norm2 = g.x * g.x + g.y * g.y + g.z * g.z;
    if (!(norm2 > 0.0)) return quat_normalized(turned);
    /* g in the earth frame of the turned q, (q (x) dq) g = q (dq g), and the rotation that levels it */
    Quat level = level_quat(quat_rotate(q, quat_rotate(dq, g)), sqrt(norm2));
    Quat out = quat_multiply(level, turned);
    /* |level (x) turned| = |level| |turned|, at hand before the product */
    double inv = 1.0 / sqrt((level.w * level.w + level.x * level.x + level.y * level.y + level.z * level.z) *
                            (turned.w * turned.w + turned.x * turned.x + turned.y * turned.y + turned.z * turned.z));
    return (Quat){out.w * inv, out.x * inv, out.y * inv, out.z * inv};
}

/* One sample: the n rows of X turned by -gyr Ts (the exact rotation of the sample), the
 * zero-order-hold filter applied to acc, the gravity estimate written to g_out and q levelled
 * onto it; X and q in place. */
void sensor_frame_step(Vec3 *X, Quat *q, const double gyr[3], const double acc[3], int n, const double *Ad,
                       const double *Bd, const double *C, double D, double Ts, double g_out[3]);

/* The gravity to start at rest on before the first sample: acc0 (m/s^2, at the end of the
 * first interval) turned back by that interval's rotation gyr0 Ts. */
void start_gravity(const double gyr0[3], const double acc0[3], double Ts, double out[3]);

/* The sensor-frame stepper's state (SENSOR_FRAME_STATE_SIZE(d->n) values: X row by row, then q)
 * at rest on acc0 (m/s^2), q the identity. */
void sensor_frame_initial_state(const DiscreteFilter *d, const double acc0[3], double *state);

#endif
