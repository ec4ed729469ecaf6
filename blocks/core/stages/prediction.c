/* prediction.c: the accelerometer predicted through the gyro (see prediction.h). */
#include "prediction.h"

#include "quaternion.h"

double prediction_error(size_t n, const double *gyr, const double *acc, const double *gravity, double Ts, size_t m,
                        double *work)
{
    if (n <= m || m == 0) return -1.0;
    Quat q = {1.0, 0.0, 0.0, 0.0}; /* the sensor's frame at t_k in that at t_0 */
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        const double *w = gyr + 3 * k, *a = acc + 3 * k, *g = gravity + 3 * k;
        double *held = work + 3 * (k % m); /* g_(k-m) in the frame at t_0, then g_k */
        q = quat_normalized(quat_multiply(q, rotvec_quat(w[0] * Ts, w[1] * Ts, w[2] * Ts)));
        if (k >= m) {
            Vec3 y = quat_rotate(q, (Vec3){a[0], a[1], a[2]});
            double dx = y.x - held[0], dy = y.y - held[1], dz = y.z - held[2];
            sum += dx * dx + dy * dy + dz * dz;
        }
        Vec3 up = quat_rotate(q, (Vec3){g[0], g[1], g[2]});
        held[0] = up.x, held[1] = up.y, held[2] = up.z;
    }
    return sum / (double)(n - m);
}
