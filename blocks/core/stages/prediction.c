/* prediction.c: the accelerometer predicted through the gyro (see prediction.h). */
#include "prediction.h"

#include "quaternion.h"

size_t prediction_errors_of(size_t count, size_t n, const double *gyr, const double *acc, const double *gravity,
                            size_t stride, double Ts, size_t m, size_t block, double *work, double *means)
{
    if (n <= m || m == 0 || block == 0 || count == 0 || count > PREDICTION_MAX_COUNT) return 0;
    Quat q = {1.0, 0.0, 0.0, 0.0}; /* the sensor's frame at t_k in that at t_0 */
    double sum[PREDICTION_MAX_COUNT] = {0.0};
    size_t blocks = 0, counted = 0, per = (n - m + block - 1) / block;
    for (size_t k = 0; k < n; k++) {
        const double *w = gyr + 3 * k, *a = acc + 3 * k;
        q = quat_turned(q, w, Ts);
        Vec3 y = quat_rotate(q, (Vec3){a[0], a[1], a[2]});
        int last = k >= m && (++counted == block || k == n - 1);
        for (size_t c = 0; c < count; c++) {
            const double *g = gravity + c * stride + 3 * k;
            double *held = work + 3 * (c * m + k % m); /* g_(k-m) in the frame at t_0, then g_k */
            if (k >= m) {
                double dx = y.x - held[0], dy = y.y - held[1], dz = y.z - held[2];
                sum[c] += dx * dx + dy * dy + dz * dz;
                if (last) {
                    means[c * per + blocks] = sum[c] / (double)counted;
                    sum[c] = 0.0;
                }
            }
            Vec3 up = quat_rotate(q, (Vec3){g[0], g[1], g[2]});
            held[0] = up.x, held[1] = up.y, held[2] = up.z;
        }
        if (last) blocks++, counted = 0;
    }
    return blocks;
}

size_t prediction_errors(size_t n, const double *gyr, const double *acc, const double *gravity, double Ts, size_t m,
                         size_t block, double *work, double *means)
{
    return prediction_errors_of(1, n, gyr, acc, gravity, 3 * n, Ts, m, block, work, means);
}

double prediction_error(size_t n, const double *gyr, const double *acc, const double *gravity, double Ts, size_t m,
                        double *work)
{
    double mean;
    return prediction_errors(n, gyr, acc, gravity, Ts, m, n > m ? n - m : 1, work, &mean) ? mean : -1.0;
}
