/* quaternion.c: quaternions and vectors (see quaternion.h). */
#include "quaternion.h"

#include <math.h>

Vec3 quat_euler_zyx(Quat q)
{
    double roll = atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y));
    double sine = 2.0 * (q.w * q.y - q.z * q.x);
    double pitch = asin(sine > 1.0 ? 1.0 : sine < -1.0 ? -1.0 : sine);
    double yaw = atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
    return (Vec3){roll, pitch, yaw};
}

void integrate_rates(size_t n, const double *gyr, double Ts, double *quat)
{
    Quat q = {1.0, 0.0, 0.0, 0.0};
    for (size_t k = 0; k < n; k++) {
        q = quat_turned(q, gyr + 3 * k, Ts);
        quat_store(q, quat + 4 * k);
    }
}
