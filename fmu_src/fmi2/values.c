/* values.c: fmi2Get* and fmi2Set* (values.h). */
#include "values.h"

#include <string.h>

#include "instance.h"

static const char *const TYPE_NAMES[] = {"Real", "Integer", "Boolean", "String"};
static const char *const CAUSALITY_NAMES[] = {"parameter", "calculated parameter", "input", "output", "local",
                                              "independent"};
static const char *const VARIABILITY_NAMES[] = {"constant", "fixed", "tunable", "discrete", "continuous"};

/* the variable of value reference vr if it has the type, else NULL with an error logged */
static const Fmi2Variable *variable(Fmi2Instance *instance, const char *call, Fmi2Type type, fmi2ValueReference vr) {
    if (vr >= fmi2_model.n_variables) {
        fmi2_log(instance, fmi2Error, "%s: no variable has the value reference %u", call, vr);
        return NULL;
    }
    const Fmi2Variable *v = &fmi2_model.variables[vr];
    if (v->type != type) {
        fmi2_log(instance, fmi2Error, "%s: value reference %u is %s, a %s variable", call, vr, v->name,
                 TYPE_NAMES[v->type]);
        return NULL;
    }
    return v;
}

/* whether a set of v is allowed in the instance's state (FMI 2.0, section 2.2.7), else an error logged */
static int settable(Fmi2Instance *instance, const char *call, const Fmi2Variable *v) {
    int before = instance->phase == FMI2_INSTANTIATED || instance->phase == FMI2_INITIALIZATION_MODE;
    int allowed;
    if (v->variability == FMI2_CONSTANT) allowed = 0;
    else if (v->causality == FMI2_INPUT) allowed = 1;
    else if (before) allowed = v->initial == FMI2_EXACT || v->initial == FMI2_APPROX;
    else allowed = v->causality == FMI2_PARAMETER && v->variability == FMI2_TUNABLE;
    if (!allowed) {
        fmi2_log(instance, fmi2Error, "%s: %s is a %s %s: it cannot be set in the state %s%s", call, v->name,
                 VARIABILITY_NAMES[v->variability], CAUSALITY_NAMES[v->causality], fmi2_phase_name(instance->phase),
                 v->causality == FMI2_PARAMETER && v->variability == FMI2_FIXED
                     ? " (set it before fmi2ExitInitializationMode)" : "");
    }
    return allowed;
}

fmi2Status fmi2_get_values(Fmi2Instance *instance, const char *call, Fmi2Type type, const fmi2ValueReference vr[],
                           size_t n, void *values) {
    if (n > 0 && (!vr || !values)) {
        fmi2_log(instance, fmi2Error, "%s: NULL value references or values for %zu variables", call, n);
        return fmi2Error;
    }
    for (size_t i = 0; i < n; i++) {
        const Fmi2Variable *v = variable(instance, call, type, vr[i]);
        if (!v) return fmi2Error;
        switch (type) {
        case FMI2_REAL: ((fmi2Real *)values)[i] = instance->reals[v->index]; break;
        case FMI2_INTEGER: ((fmi2Integer *)values)[i] = instance->integers[v->index]; break;
        case FMI2_BOOLEAN: ((fmi2Boolean *)values)[i] = instance->booleans[v->index]; break;
        case FMI2_STRING: ((fmi2String *)values)[i] = instance->strings[v->index]; break;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2_set_values(Fmi2Instance *instance, const char *call, Fmi2Type type, const fmi2ValueReference vr[],
                           size_t n, const void *values) {
    if (n > 0 && (!vr || !values)) {
        fmi2_log(instance, fmi2Error, "%s: NULL value references or values for %zu variables", call, n);
        return fmi2Error;
    }
    for (size_t i = 0; i < n; i++) { /* all checked before any is set */
        const Fmi2Variable *v = variable(instance, call, type, vr[i]);
        if (!v || !settable(instance, call, v)) return fmi2Error;
        if (type == FMI2_STRING) {
            fmi2String text = ((const fmi2String *)values)[i];
            if (!text || strlen(text) >= FMI2_STRING_SIZE) {
                fmi2_log(instance, fmi2Error, "%s: %s must be a string shorter than %d bytes", call, v->name,
                         FMI2_STRING_SIZE);
                return fmi2Error;
            }
        }
    }
    for (size_t i = 0; i < n; i++) {
        size_t k = fmi2_model.variables[vr[i]].index;
        switch (type) {
        case FMI2_REAL: instance->reals[k] = ((const fmi2Real *)values)[i]; break;
        case FMI2_INTEGER: instance->integers[k] = ((const fmi2Integer *)values)[i]; break;
        case FMI2_BOOLEAN: instance->booleans[k] = ((const fmi2Boolean *)values)[i] != fmi2False; break;
        case FMI2_STRING: strcpy(instance->strings[k], ((const fmi2String *)values)[i]); break;
        }
    }
    return fmi2OK;
}
