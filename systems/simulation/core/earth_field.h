/* earth_field.h: the magnetic field of the simulated earth, and as a sensor sees it.
 * Python: systems/simulation/profile_table.py (EARTH_FIELD_UT), the same numbers; bound into
 * Python by systems/simulation/motion.py (Motion.mag). */
#ifndef SIM_EARTH_FIELD_H
#define SIM_EARTH_FIELD_H

#include <stddef.h>

/* the magnetic field in ENU, uT: northwards and down */
#define EARTH_FIELD_UT {0.0, 20.0, -45.0}

/* the field m (uT) in the coordinates of a sensor at orientation q (sensor -> earth, [w, x, y, z]) */
void earth_field_in_sensor(const double q[4], double m[3]);
/* n orientations: quat n rows of 4, m n rows of 3 */
void earth_field_run(const double *quat, size_t n, double *m);

#endif
