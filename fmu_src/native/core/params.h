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

/* resolved: the stage's defaults (NaN for None) updated by the given values (NaN: not
 * given); every index the stage lacks is NaN. 0, or -1 with resolve_params's message:
 * "unknown parameter 'x' for <owner>; known: ..." for a given value of a name the stage
 * lacks, "parameter x must be a finite positive number, got -1.0" (non-negative where the
 * parameter allows zero) for a value out of range. */
int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size);

#endif
