/* profile_params.h: the one check of a motion profile's parameters against their plausible ranges (low <= value
 * <= high, as systems/simulation/profile_table.py's Params give them, in the table the build generates from it:
 * sim_profiles.h), which MotionProfile.fmu runs at initialisation and systems/simulation/motion.py's profiles
 * through attitude_fmu._core. */
#ifndef SIM_PROFILE_PARAMS_H
#define SIM_PROFILE_PARAMS_H

#include <stddef.h>

#include "sim_profiles.h" /* SimProfile, SIM_PROFILE_MAX_PARAMS (generated) */

/* the profile of that name (SIM_PROFILES), or NULL */
const SimProfile *profile_named(const char *name);
/* values (n, in the table's order) and g within their plausible ranges: 0, or -1 with the
 * refusal naming the parameter as <profile>_<parameter> (MotionProfile.fmu's variable), its value and
 * the range */
int profile_check(const SimProfile *profile, const double *values, size_t n, double g, char *message,
                  size_t size);

#endif
