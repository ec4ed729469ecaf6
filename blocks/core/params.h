/* params.h: the tuning parameters of a stage (a method, the gyro-offset or the heading
 * estimator) and their validation. Python twin: blocks/params.py (resolve_params).
 * The tables are generated from the Python ones into af_params.h
 * (attitude_fmu.systems.fmi.native_tables); values are arrays of AF_N_PARAMS doubles
 * indexed by AF_P_<name>, NaN where a value is not given or a default is None. */
#ifndef AF_PARAMS_C_H
#define AF_PARAMS_C_H

#include <stddef.h>

#include "af_params.h"

/* The parameter of index AF_P_<name> in stage AF_STAGE_<name>, or NULL where it has none. */
const AfStageParam *stage_param(int stage, int index);

#define RANGE_TEXT_SIZE 96 /* bytes that hold any range_text */

/* Param.range_text: the plausible range of p as messages say it, "[1e-09, 1e+12] s", "[0, 1e+06] s"
 * where it allows zero, "(0, 100] s" where its low is 0; written to out (size bytes) and returned. */
const char *range_text(const AfStageParam *p, char *out, size_t size);

/* resolved: the stage's defaults (NaN for None) updated by the given values (NaN: not
 * given); every index the stage lacks is NaN. 0, or -1 with resolve_params's message:
 * "unknown parameter 'x' for <owner>; known: ..." for a given value of a name the stage
 * lacks; for a value, "parameter x must be a finite positive number (<range>), got -1.0"
 * (non-negative where the parameter allows zero), "parameter x must be 0 or 1, got 0.5
 * (<doc>)" where it has choices, "parameter x = 1e+300 s is outside its plausible range
 * <range> (<doc>)" beyond its low or high. */
int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size);

#endif
