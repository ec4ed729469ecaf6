/* values.c: fmi2Get* and fmi2Set* (values.h). */
#include "values.h"

#include <stdio.h>
#include <string.h>

#include "instance.h"

static const char *const TYPE_NAMES[] = {"a Real", "an Integer", "a Boolean", "a String", "an Enumeration"};
static const char *const CAUSALITY_NAMES[] = {"parameter", "calculated parameter", "input", "output", "local",
                                              "independent"};
static const char *const VARIABILITY_NAMES[] = {"constant", "fixed", "tunable", "discrete", "continuous"};

/* the variable of value reference vr if it has one of the types (FMI2_TYPES bits), else NULL with an error logged */
static const Fmi2Variable *variable(Fmi2Instance *instance, const char *call, unsigned types, fmi2ValueReference vr) {
    if (vr >= fmi2_model.n_variables) {
        fmi2_log(instance, fmi2Error, "%s: no variable has the value reference %u", call, vr);
        return NULL;
    }
    const Fmi2Variable *v = &fmi2_model.variables[vr];
    if (!(types & FMI2_TYPES(v->type))) {
        fmi2_log(instance, fmi2Error, "%s: value reference %u is %s, %s variable", call, vr, v->name,
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

/* whether value is one of the Enumeration v's items' (1 ... n_items), else an error logged naming them */
static int in_items(Fmi2Instance *instance, const char *call, const Fmi2Variable *v, fmi2Integer value) {
    if (value >= 1 && (size_t)value <= v->n_items) return 1;
    char items[FMI2_STRING_SIZE] = "";
    size_t used = 0;
    for (size_t k = 0; k < v->n_items && used < sizeof items; k++) {
        int n = snprintf(items + used, sizeof items - used, "%s%lu %s", k ? ", " : "", (unsigned long)(k + 1),
                         v->items[k]);
        if (n < 0) break;
        used += (size_t)n;
    }
    fmi2_log(instance, fmi2Error, "%s: %s must be one of its items (%s), got %d", call, v->name, items, (int)value);
    return 0;
}

const char *fmi2_item(Fmi2Instance *instance, size_t index) {
    for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        if (v->type == FMI2_ENUMERATION && v->index == index) {
            fmi2Integer value = instance->integers[index];
            return in_items(instance, fmi2_model.identifier, v, value) ? v->items[value - 1] : NULL;
        }
    }
    fmi2_log(instance, fmi2Error, "no Enumeration variable is held at integer %lu", (unsigned long)index);
    return NULL;
}

fmi2Status fmi2_get_values(Fmi2Instance *instance, const char *call, unsigned types, const fmi2ValueReference vr[],
                           size_t n, void *values) {
    if (n > 0 && (!vr || !values)) {
        fmi2_log(instance, fmi2Error, "%s: NULL value references or values for %lu variables", call,
                 (unsigned long)n);
        return fmi2Error;
    }
    if (types & FMI2_TYPES(FMI2_REAL)) fmi2_start_outputs(instance); /* in Initialization Mode */
    for (size_t i = 0; i < n; i++) {
        const Fmi2Variable *v = variable(instance, call, types, vr[i]);
        if (!v) return fmi2Error;
        switch (v->type) {
        case FMI2_REAL: ((fmi2Real *)values)[i] = instance->reals[v->index]; break;
        case FMI2_INTEGER:
        case FMI2_ENUMERATION: ((fmi2Integer *)values)[i] = instance->integers[v->index]; break;
        case FMI2_BOOLEAN: ((fmi2Boolean *)values)[i] = instance->booleans[v->index]; break;
        case FMI2_STRING: ((fmi2String *)values)[i] = instance->strings[v->index]; break;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2_set_values(Fmi2Instance *instance, const char *call, unsigned types, const fmi2ValueReference vr[],
                           size_t n, const void *values) {
    if (n > 0 && (!vr || !values)) {
        fmi2_log(instance, fmi2Error, "%s: NULL value references or values for %lu variables", call,
                 (unsigned long)n);
        return fmi2Error;
    }
    for (size_t i = 0; i < n; i++) { /* all checked before any is set */
        const Fmi2Variable *v = variable(instance, call, types, vr[i]);
        if (!v || !settable(instance, call, v)) return fmi2Error;
        if (v->type == FMI2_ENUMERATION && !in_items(instance, call, v, ((const fmi2Integer *)values)[i]))
            return fmi2Error;
        if (v->type == FMI2_STRING) {
            fmi2String text = ((const fmi2String *)values)[i];
            if (!text || strlen(text) >= FMI2_STRING_SIZE) {
                fmi2_log(instance, fmi2Error, "%s: %s must be a string shorter than %d bytes", call, v->name,
                         FMI2_STRING_SIZE);
                return fmi2Error;
            }
        }
    }
    for (size_t i = 0; i < n; i++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr[i]];
        size_t k = v->index;
        switch (v->type) {
        case FMI2_REAL: instance->reals[k] = ((const fmi2Real *)values)[i]; break;
        case FMI2_INTEGER:
        case FMI2_ENUMERATION: instance->integers[k] = ((const fmi2Integer *)values)[i]; break;
        case FMI2_BOOLEAN: instance->booleans[k] = ((const fmi2Boolean *)values)[i] != fmi2False; break;
        case FMI2_STRING: strcpy(instance->strings[k], ((const fmi2String *)values)[i]); break;
        }
    }
    return fmi2OK;
}
