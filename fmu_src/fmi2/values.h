/* values.h: fmi2Get* and fmi2Set* on an instance's values, each value reference checked for its
 * type, and each set for what the variable's causality, variability and initial allow in the
 * instance's state (FMI 2.0, section 2.2.7). */
#ifndef FMI2_VALUES_H
#define FMI2_VALUES_H

#include "fmi2_model.h"

/* values: an array of n values of the type (fmi2Real, fmi2Integer, fmi2Boolean or fmi2String).
 * fmi2OK, or fmi2Error with a message naming the call and the variable; a refused set changes
 * none of the values. */
fmi2Status fmi2_get_values(Fmi2Instance *instance, const char *call, Fmi2Type type, const fmi2ValueReference vr[],
                           size_t n, void *values);
fmi2Status fmi2_set_values(Fmi2Instance *instance, const char *call, Fmi2Type type, const fmi2ValueReference vr[],
                           size_t n, const void *values);

#endif
