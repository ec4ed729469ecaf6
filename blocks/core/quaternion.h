/* quaternion.h: scalar-first unit quaternions [w, x, y, z] and 3-vectors.
 * Python twin: blocks/quaternion.py (every function here has the same name there). */
#ifndef AF_QUATERNION_H
#define AF_QUATERNION_H

typedef struct { double w, x, y, z; } Quat;
typedef struct { double x, y, z; } Vec3;

#define SERIES_ANGLE2 1e-2 /* (rad)^2: below it the half-angle series to theta^8 is exact to double precision */

Quat rotvec_quat(double rx, double ry, double rz);       /* the rotation vector (rad) as a quaternion */
Quat quat_multiply(Quat p, Quat q);                      /* Hamilton product p (x) q */
Vec3 quat_rotate(Quat q, Vec3 v);                        /* v rotated by the unit quaternion q */
void quat_matrix(Quat q, double m[9]);                   /* rotation matrix of q, row-major */
Quat quat_normalized(Quat q);                            /* q scaled to unit norm */
Quat level_quat(Vec3 u, double norm);                    /* smallest rotation of u (length norm > 0) onto +z, unnormalised */
Vec3 quat_euler_zyx(Quat q);                             /* roll, pitch, yaw (rad) of the Z-Y-X sequence */
Vec3 up_in_sensor(Quat q);                               /* earth up in sensor coordinates: R(q)^T z */
Quat quat_conjugate(Quat q);                             /* the inverse of a unit quaternion */
Quat quat_load(const double q[4]);                       /* the quaternion a state array holds in q[0..3] */
void quat_store(Quat q, double out[4]);                  /* q into a state array's out[0..3] */
/* a kernel method's output for one sample: gravity g up (m/s^2, g the magnitude) and quat = q */
void write_sample(double gravity[3], double quat[4], double g, Vec3 up, const double q[4]);

#endif
