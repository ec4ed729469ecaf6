/* delays.c: the per-span kernel of the magnetometer's delay measurement (blocks/stages/delays.py). */
#include "stages/delays.h"

#include "quaternion.h"

/* the sensor at the fractional sample index x, within [0, last] (last >= 1) */
static Quat sensor_at(const double *quat, const double *gyr, double Ts, size_t last, double x)
{
    x = x < 0.0 ? 0.0 : x;
    x = x > (double)last ? (double)last : x;
    size_t k = (size_t)x;
    k = k < last - 1 ? k : last - 1;
    double f = (x - (double)k) * Ts;
    const double *w = gyr + 3 * (k + 1);
    return quat_multiply(quat_load(quat + 4 * k), rotvec_quat(f * w[0], f * w[1], f * w[2]));
}

void carry_spans(size_t n, const double *quat, const double *gyr, double Ts, size_t spans, const double *x0,
                 const double *x1, double *matrices)
{
    for (size_t j = 0; j < spans; j++) {
        Quat q0 = sensor_at(quat, gyr, Ts, n - 1, x0[j]), q1 = sensor_at(quat, gyr, Ts, n - 1, x1[j]);
        quat_matrix(quat_multiply(quat_conjugate(q1), q0), matrices + 9 * j); /* R_D^T = q1^-1 (x) q0 */
    }
}
