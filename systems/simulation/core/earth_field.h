/* earth_field.h: the magnetic field of the simulated earth.
 * Python twin: systems/simulation/motion.py (EARTH_FIELD_UT). */
#ifndef SIM_EARTH_FIELD_H
#define SIM_EARTH_FIELD_H

/* the magnetic field in ENU, uT: northwards and down */
#define EARTH_FIELD_UT {0.0, 20.0, -45.0}

#endif
