/* params.h: the tuning parameters of a stage (a method, the gyro-offset or the heading
 * estimator) and their validation, the one validator of the package (blocks.params holds
 * the Param fields and range_text for help texts). The tables are generated from
 * blocks/tuning.py into af_params.h (blocks/core/generate_tables.py); resolved values are
 * arrays of AF_N_PARAMS doubles indexed by AF_P_<name>, NaN where a default is None. */
#ifndef AF_PARAMS_C_H
#define AF_PARAMS_C_H

#include <stddef.h>

#include "af_params.h"

/* A value given for a tuning parameter by name, as a caller hands it over. */
typedef struct {
    const char *name;  /* any string: names no stage has are refused */
    double value;      /* NaN where the value is not a number */
    const char *shown; /* the value as messages show it: NULL, Python's repr of the float value; else
                          the caller's text (a Python value that is not a number: its repr) */
} AfGiven;

/* AF_P_<name> of the tuning parameter called name, or -1. */
int param_index(const char *name);

/* The parameter of index AF_P_<name> in stage AF_STAGE_<name>, or NULL where it has none. */
const AfStageParam *stage_param(int stage, int index);

/* The parameter called name in stage AF_STAGE_<name>, or NULL where it has none. */
const AfStageParam *stage_param_named(int stage, const char *name);

/* The values of an array of AF_N_PARAMS (NaN: not given) as a list, in index order (the
 * order of the FMU's variables); returns their count. */
int given_values(const double values[AF_N_PARAMS], AfGiven given[AF_N_PARAMS]);

#define RANGE_TEXT_SIZE 96 /* bytes that hold any range_text */

/* Param.range_text: the plausible range of p as messages say it, "[1e-09, 1e+12] s", "[0, 1e+06] s"
 * where it allows zero, "(0, 100] s" where its low is 0; written to out (size bytes) and returned. */
const char *range_text(const AfStageParam *p, char *out, size_t size);

/* resolved: the stage's defaults (NaN for None) updated by the n given values, taken in their
 * order; every index the stage lacks is NaN. 0, or -1 with the message of the first refused:
 * "unknown parameter 'x' for <owner>; known: ..." for a name the stage lacks; for a value,
 * "parameter x must be a finite positive number (<range>), got -1.0" (non-negative where the
 * parameter allows zero; a value that is not a number is refused so too), "parameter x must be
 * 0 or 1, got 0.5 (<doc>)" where it has choices, "parameter x = 1e+300 s is outside its plausible
 * range <range> (<doc>)" beyond its low or high. */
int resolve_given(int stage, const AfGiven *given, int n, double resolved[AF_N_PARAMS], char *message, size_t size);

/* resolve_given with the values of an array of AF_N_PARAMS (NaN: not given), in index order. */
int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size);

#endif
