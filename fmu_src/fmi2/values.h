/* values.h: fmi2Get* and fmi2Set* on an instance's values, each value reference checked for its
 * type, and each set for what the variable's causality, variability and initial allow in the
 * instance's state (FMI 2.0, section 2.2.7). */
#ifndef FMI2_VALUES_H
#define FMI2_VALUES_H

#include "fmi2_model.h"

/* A set of variable types, of which a call reaches the variables: FMI 2.0's fmi2GetInteger and
 * fmi2SetInteger reach Integer and Enumeration variables, FMI 3.0's Int32 calls Integer ones and its
 * Int64 calls Enumeration ones. */
#define FMI2_TYPES(type) (1u << (type))
#define FMI2_INTEGERS (FMI2_TYPES(FMI2_INTEGER) | FMI2_TYPES(FMI2_ENUMERATION))

/* values: an array of n values as the types hold them (fmi2Real, fmi2Integer for Integer and
 * Enumeration, fmi2Boolean or fmi2String); types: FMI2_TYPES bits. fmi2OK, or fmi2Error with a
 * message naming the call and the variable (an Enumeration's value out of its items' range: with
 * them); a refused set changes none of the values. */
fmi2Status fmi2_get_values(Fmi2Instance *instance, const char *call, unsigned types, const fmi2ValueReference vr[],
                           size_t n, void *values);
fmi2Status fmi2_set_values(Fmi2Instance *instance, const char *call, unsigned types, const fmi2ValueReference vr[],
                           size_t n, const void *values);

#endif
