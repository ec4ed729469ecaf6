/* earth_field.c: the earth's field in sensor coordinates. */
#include "earth_field.h"

#include "quaternion.h"

void earth_field_in_sensor(const double q[4], double m[3]) {
    const double earth[3] = EARTH_FIELD_UT;
    Vec3 v = quat_rotate((Quat){q[0], -q[1], -q[2], -q[3]}, (Vec3){earth[0], earth[1], earth[2]});
    m[0] = v.x, m[1] = v.y, m[2] = v.z;
}

void earth_field_run(const double *quat, size_t n, double *m) {
    for (size_t k = 0; k < n; k++) earth_field_in_sensor(quat + 4 * k, m + 3 * k);
}
