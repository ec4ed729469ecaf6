/* quaternion.c: Python twin blocks/quaternion.py; the same operations in the same order. */
#include "quaternion.h"

#include <math.h>

Quat rotvec_quat(double rx, double ry, double rz)
{
    double angle2 = rx * rx + ry * ry + rz * rz;
    double c, s;
    if (angle2 < SERIES_ANGLE2) {
        /* cos(theta/2) and sin(theta/2)/theta by their Taylor series */
        c = 1.0 - angle2 / 8.0 * (1.0 - angle2 / 48.0 * (1.0 - angle2 / 120.0 * (1.0 - angle2 / 224.0)));
        s = 0.5 * (1.0 - angle2 / 24.0 * (1.0 - angle2 / 80.0 * (1.0 - angle2 / 168.0 * (1.0 - angle2 / 288.0))));
    } else {
        double angle = sqrt(angle2);
        c = cos(0.5 * angle);
        s = sin(0.5 * angle) / angle;
    }
    return (Quat){c, rx * s, ry * s, rz * s};
}

Quat quat_multiply(Quat p, Quat q)
{
    return (Quat){
        p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z,
        p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
        p.w * q.y - p.x * q.z + p.y * q.w + p.z * q.x,
        p.w * q.z + p.x * q.y - p.y * q.x + p.z * q.w,
    };
}

Vec3 quat_rotate(Quat q, Vec3 v)
{
    double tx = 2.0 * (q.y * v.z - q.z * v.y);
    double ty = 2.0 * (q.z * v.x - q.x * v.z);
    double tz = 2.0 * (q.x * v.y - q.y * v.x);
    return (Vec3){
        v.x + q.w * tx + q.y * tz - q.z * ty,
        v.y + q.w * ty + q.z * tx - q.x * tz,
        v.z + q.w * tz + q.x * ty - q.y * tx,
    };
}

void quat_matrix(Quat q, double m[9])
{
    m[0] = 1.0 - 2.0 * (q.y * q.y + q.z * q.z);
    m[1] = 2.0 * (q.x * q.y - q.w * q.z);
    m[2] = 2.0 * (q.x * q.z + q.w * q.y);
    m[3] = 2.0 * (q.x * q.y + q.w * q.z);
    m[4] = 1.0 - 2.0 * (q.x * q.x + q.z * q.z);
    m[5] = 2.0 * (q.y * q.z - q.w * q.x);
    m[6] = 2.0 * (q.x * q.z - q.w * q.y);
    m[7] = 2.0 * (q.y * q.z + q.w * q.x);
    m[8] = 1.0 - 2.0 * (q.x * q.x + q.y * q.y);
}

Quat quat_normalized(Quat q)
{
    double inv = 1.0 / sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    return (Quat){q.w * inv, q.x * inv, q.y * inv, q.z * inv};
}

Quat level_quat(Vec3 u, double norm)
{
    double horizontal2 = u.x * u.x + u.y * u.y;
    double w;
    if (u.z >= 0.0) {
        w = norm + u.z;
    } else if (horizontal2 < 1e-30 * norm * norm) {
        return (Quat){0.0, 1.0, 0.0, 0.0}; /* upside down: the half turn about x */
    } else {
        w = horizontal2 / (norm - u.z); /* = norm + u.z, without cancellation */
    }
    return (Quat){w, u.y, -u.x, 0.0};
}

Vec3 quat_euler_zyx(Quat q)
{
    double roll = atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y));
    double sine = 2.0 * (q.w * q.y - q.z * q.x);
    double pitch = asin(sine > 1.0 ? 1.0 : sine < -1.0 ? -1.0 : sine);
    double yaw = atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
    return (Vec3){roll, pitch, yaw};
}

Quat quat_conjugate(Quat q)
{
    return (Quat){q.w, -q.x, -q.y, -q.z};
}

Vec3 up_in_sensor(Quat q)
{
    return quat_rotate(quat_conjugate(q), (Vec3){0.0, 0.0, 1.0});
}

Quat quat_load(const double q[4])
{
    return (Quat){q[0], q[1], q[2], q[3]};
}

void quat_store(Quat q, double out[4])
{
    out[0] = q.w;
    out[1] = q.x;
    out[2] = q.y;
    out[3] = q.z;
}

void write_sample(double gravity[3], double quat[4], double g, Vec3 up, const double q[4])
{
    gravity[0] = g * up.x;
    gravity[1] = g * up.y;
    gravity[2] = g * up.z;
    quat_store(quat_load(q), quat);
}
