/* quaternion.h: scalar-first unit quaternions [w, x, y, z] and 3-vectors. The small steps are
 * defined here, inline, for the per-sample loops that use them. */
#ifndef AF_QUATERNION_H
#define AF_QUATERNION_H

#include <math.h>
#include <stddef.h>

typedef struct { double w, x, y, z; } Quat;
typedef struct { double x, y, z; } Vec3;

#define AF_PI 3.14159265358979323846 /* rad */
#define SERIES_ANGLE2 1e-2 /* (rad)^2: below it the half-angle series to theta^8 is exact to double precision */

/* the quaternion a state array holds in q[0..3] */
static inline Quat quat_load(const double q[4])
{
    return (Quat){q[0], q[1], q[2], q[3]};
}

/* q into a state array's out[0..3] */
static inline void quat_store(Quat q, double out[4])
{
    out[0] = q.w;
    out[1] = q.x;
    out[2] = q.y;
    out[3] = q.z;
}

/* the inverse of a unit quaternion */
static inline Quat quat_conjugate(Quat q)
{
    return (Quat){q.w, -q.x, -q.y, -q.z};
}

/* the rotation vector (rad) as a quaternion */
static inline Quat rotvec_quat(double rx, double ry, double rz)
{
    double angle2 = rx * rx + ry * ry + rz * rz;
    double c, s;
    if (angle2 < SERIES_ANGLE2) {
        /* cos(theta/2) and sin(theta/2)/theta by their Taylor series, the divisions by the terms'
         * ratios (8, 48, 120, 224; 24, 80, 168, 288) as products with their reciprocals */
        c = 1.0 - angle2 * 0.125 * (1.0 - angle2 * (1.0 / 48.0) * (1.0 - angle2 * (1.0 / 120.0) *
                                                                   (1.0 - angle2 * (1.0 / 224.0))));
        s = 0.5 * (1.0 - angle2 * (1.0 / 24.0) * (1.0 - angle2 * (1.0 / 80.0) * (1.0 - angle2 * (1.0 / 168.0) *
                                                                                 (1.0 - angle2 * (1.0 / 288.0)))));
    } else {
        double angle = sqrt(angle2);
        c = cos(0.5 * angle);
        s = sin(0.5 * angle) / angle;
    }
    return (Quat){c, rx * s, ry * s, rz * s};
}

/* Hamilton product p (x) q */
static inline Quat quat_multiply(Quat p, Quat q)
{
    return (Quat){
        p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z,
        p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
        p.w * q.y - p.x * q.z + p.y * q.w + p.z * q.x,
        p.w * q.z + p.x * q.y - p.y * q.x + p.z * q.w,
    };
}

/* v rotated by the unit quaternion q */
static inline Vec3 quat_rotate(Quat q, Vec3 v)
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

/* rotation matrix of q, row-major */
static inline void quat_matrix(Quat q, double m[9])
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

/* q scaled to unit norm */
static inline Quat quat_normalized(Quat q)
{
    double inv = 1.0 / sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    return (Quat){q.w * inv, q.x * inv, q.y * inv, q.z * inv};
}

/* q turned by the mean rate w (rad/s, 3, sensor coordinates) over Ts s, normalised: one step of the gyro's
 * integration */
static inline Quat quat_turned(Quat q, const double w[3], double Ts)
{
    return quat_normalized(quat_multiply(q, rotvec_quat(w[0] * Ts, w[1] * Ts, w[2] * Ts)));
}

/* smallest rotation of u (length norm > 0) onto +z, unnormalised: w = norm + u.z; upside down (u along -z),
 * the half turn about x */
static inline Quat level_quat(Vec3 u, double norm)
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

/* earth up in sensor coordinates: R(q)^T z */
static inline Vec3 up_in_sensor(Quat q)
{
    return quat_rotate(quat_conjugate(q), (Vec3){0.0, 0.0, 1.0});
}

/* a kernel method's output for one sample: gravity g up (m/s^2, g the magnitude) and quat = q */
static inline void write_sample(double gravity[3], double quat[4], double g, Vec3 up, Quat q)
{
    gravity[0] = g * up.x;
    gravity[1] = g * up.y;
    gravity[2] = g * up.z;
    quat_store(q, quat);
}

/* roll, pitch, yaw (rad) of the Z-Y-X sequence */
Vec3 quat_euler_zyx(Quat q);

/* quat[k] (n x 4): the orientation after gyro sample k (n x 3 mean rates, rad/s, over Ts s each)
 * from the identity before the first, q <- q (x) exp(w Ts). */
void integrate_rates(size_t n, const double *gyr, double Ts, double *quat);

#endif
