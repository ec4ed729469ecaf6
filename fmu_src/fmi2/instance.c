/* instance.c: an FMU instance's life, its state machine and its logging (instance.h). */
#include "instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MESSAGE_SIZE 2048
#define STATE_ALIGNMENT 16 /* the model's state starts at a multiple of it within the data block */

static const char *const PHASE_NAMES[FMI2_N_PHASES] = {
    "instantiated", "initialization mode", "step complete (initialised)", "terminated", "error",
};

const char *fmi2_phase_name(int phase) {
    return phase >= 0 && phase < FMI2_N_PHASES ? PHASE_NAMES[phase] : "unknown";
}

/* the category of a message of the status: pythonfmu's names, and the trace for fmi2OK */
static const char *category_of(fmi2Status status) {
    switch (status) {
    case fmi2Warning: return "logStatusWarning";
    case fmi2Discard: return "logStatusDiscard";
    case fmi2Error: return "logStatusError";
    case fmi2Fatal: return "logStatusFatal";
    default: return "logCalls";
    }
}

static int category_index(const char *name) {
    for (size_t k = 0; k < fmi2_model.n_log_categories; k++)
        if (strcmp(fmi2_model.log_categories[k], name) == 0) return (int)k;
    return -1;
}

/* pass text on to the logger, which reads its message as a printf format: every % doubled */
static void deliver(const fmi2CallbackFunctions *functions, fmi2String name, fmi2Status status, const char *category,
                    const char *format, va_list args) {
    char text[MESSAGE_SIZE], escaped[2 * MESSAGE_SIZE];
    vsnprintf(text, sizeof text, format, args);
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    functions->logger(functions->componentEnvironment, name ? name : "", status, category, escaped);
}

void fmi2_log_to(const fmi2CallbackFunctions *functions, fmi2String name, fmi2Status status, const char *format,
                 ...) {
    if (!functions || !functions->logger) return;
    va_list args;
    va_start(args, format);
    deliver(functions, name, status, category_of(status), format, args);
    va_end(args);
}

static int wanted(const Fmi2Instance *instance, fmi2Status status) {
    if (status != fmi2OK) return 1; /* warnings and errors always */
    if (!instance->debug) return 0;
    int own = category_index(category_of(status)), all = category_index("logAll");
    return (own >= 0 && (instance->categories >> own & 1u)) || (all >= 0 && (instance->categories >> all & 1u));
}

void fmi2_log(Fmi2Instance *instance, fmi2Status status, const char *format, ...) {
    if (status > instance->logged) instance->logged = status;
    if (!instance->callbacks.logger || !wanted(instance, status)) return;
    va_list args;
    va_start(args, format);
    deliver(&instance->callbacks, instance->name, status, category_of(status), format, args);
    va_end(args);
}

void fmi2_set_debug_logging(Fmi2Instance *instance, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    unsigned long every = fmi2_model.n_log_categories >= 8 * sizeof(unsigned long)
                              ? ~0ul
                              : (1ul << fmi2_model.n_log_categories) - 1ul;
    if (n == 0) {
        instance->categories = on ? every : 0ul;
    } else {
        for (size_t i = 0; i < n; i++) {
            int k = categories && categories[i] ? category_index(categories[i]) : -1;
            if (k < 0) {
                fmi2_log(instance, fmi2Warning, "fmi2SetDebugLogging: unknown log category \"%s\" ignored",
                         categories && categories[i] ? categories[i] : "(null)");
            } else if (on) {
                instance->categories |= 1ul << k;
            } else {
                instance->categories &= ~(1ul << k);
            }
        }
    }
    instance->debug = instance->categories != 0;
}

/* offsets of the reals, integers, booleans, strings and state within the data block; returns its size */
static size_t layout(size_t offsets[5]) {
    const Fmi2Model *m = &fmi2_model;
    offsets[0] = 0;
    offsets[1] = offsets[0] + m->n_reals * sizeof(fmi2Real);
    offsets[2] = offsets[1] + m->n_integers * sizeof(fmi2Integer);
    offsets[3] = offsets[2] + m->n_booleans * sizeof(fmi2Boolean);
    size_t end = offsets[3] + m->n_strings * FMI2_STRING_SIZE;
    offsets[4] = (end + STATE_ALIGNMENT - 1) / STATE_ALIGNMENT * STATE_ALIGNMENT;
    return offsets[4] + m->state_size;
}

void fmi2_instance_reset(Fmi2Instance *instance) {
    memset(instance->data, 0, instance->data_size);
    for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        switch (v->type) {
        case FMI2_REAL: instance->reals[v->index] = v->start; break;
        case FMI2_INTEGER:
        case FMI2_ENUMERATION: instance->integers[v->index] = (fmi2Integer)v->start; break;
        case FMI2_BOOLEAN: instance->booleans[v->index] = v->start != 0.0; break;
        case FMI2_STRING:
            strncpy(instance->strings[v->index], v->start_string, FMI2_STRING_SIZE - 1);
            break;
        }
    }
    instance->phase = FMI2_INSTANTIATED;
    instance->time = 0.0;
    instance->start_time = 0.0;
}

size_t fmi2_data_size(void) {
    size_t offsets[5];
    return layout(offsets);
}

void fmi2_instance_bind(Fmi2Instance *instance, unsigned char *data) {
    size_t offsets[5];
    instance->data = data;
    instance->data_size = layout(offsets);
    instance->reals = (fmi2Real *)(void *)(data + offsets[0]);
    instance->integers = (fmi2Integer *)(void *)(data + offsets[1]);
    instance->booleans = (fmi2Boolean *)(void *)(data + offsets[2]);
    instance->strings = (char (*)[FMI2_STRING_SIZE])(void *)(data + offsets[3]);
    instance->state = data + offsets[4];
}

Fmi2Instance *fmi2_instance_new(fmi2String name, const fmi2CallbackFunctions *functions, fmi2Boolean logging_on) {
    size_t size = fmi2_data_size();
    Fmi2Instance *instance = calloc(1, sizeof *instance);
    unsigned char *data = calloc(1, size ? size : 1);
    char *copy = malloc(strlen(name ? name : "") + 1);
    if (!instance || !data || !copy) {
        free(instance);
        free(data);
        free(copy);
        fmi2_log_to(functions, name, fmi2Error, "fmi2Instantiate: out of memory");
        return NULL;
    }
    strcpy(copy, name ? name : "");
    instance->name = copy;
    instance->callbacks = *functions;
    fmi2_instance_bind(instance, data);
    fmi2_set_debug_logging(instance, logging_on, 0, NULL);
    fmi2_instance_reset(instance);
    return instance;
}

void fmi2_instance_free(Fmi2Instance *instance) {
    fmi2_free_states(instance);
    free(instance->data);
    free(instance->name);
    free(instance);
}

fmi2Status fmi2_scratch(const Fmi2Instance *view, Fmi2Instance *scratch) {
    memset(scratch, 0, sizeof *scratch); /* no logger: the initialisation's messages go nowhere */
    unsigned char *data = malloc(view->data_size ? view->data_size : 1);
    if (!data) return fmi2Error;
    memcpy(data, view->data, view->data_size);
    fmi2_instance_bind(scratch, data);
    memset(scratch->state, 0, fmi2_model.state_size);
    scratch->phase = FMI2_INITIALIZATION_MODE;
    scratch->time = scratch->start_time = view->start_time;
    return fmi2_model.initialise(scratch);
}

fmi2Status fmi2_initialise(Fmi2Instance *instance) {
    fmi2Status status = fmi2_model.initialise(instance);
    if (status >= fmi2Error) return status;
    if (fmi2_model.start) fmi2_model.start(instance);
    instance->phase = FMI2_STEP_COMPLETE;
    return status;
}

void fmi2_start_outputs(Fmi2Instance *instance) {
    if (!fmi2_model.start || instance->phase != FMI2_INITIALIZATION_MODE) return;
    Fmi2Instance scratch;
    if (fmi2_scratch(instance, &scratch) < fmi2Error) {
        fmi2_model.start(&scratch);
        for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
            const Fmi2Variable *v = &fmi2_model.variables[vr];
            if (v->type == FMI2_REAL && v->causality == FMI2_OUTPUT && v->initial == FMI2_CALCULATED)
                instance->reals[v->index] = scratch.reals[v->index];
        }
    }
    free(scratch.data);
}

int fmi2_enter(Fmi2Instance *instance, const char *call, unsigned allowed) {
    instance->logged = fmi2OK;
    fmi2_log(instance, fmi2OK, "%s", call);
    if (allowed & FMI2_IN(instance->phase)) return 1;
    char states[256] = "";
    for (int p = 0; p < FMI2_N_PHASES; p++) {
        if (!(allowed & FMI2_IN(p))) continue;
        if (states[0]) strncat(states, ", ", sizeof states - strlen(states) - 1);
        strncat(states, PHASE_NAMES[p], sizeof states - strlen(states) - 1);
    }
    fmi2_log(instance, fmi2Error, "%s is not allowed in the state %s (only in: %s)", call,
             fmi2_phase_name(instance->phase), states);
    instance->phase = FMI2_ERROR;
    return 0;
}

fmi2Status fmi2_leave_unchanged(Fmi2Instance *instance, fmi2Status status) {
    return instance->logged > status ? instance->logged : status;
}

fmi2Status fmi2_leave(Fmi2Instance *instance, fmi2Status status) {
    if (instance->logged > status) status = instance->logged;
    if (status >= fmi2Error) instance->phase = FMI2_ERROR;
    return status;
}

int fmi2_step_allowed(Fmi2Instance *instance, const char *call, double t, double h) {
    if (isfinite(t) && isfinite(h) && h > 0.0) return 1;
    fmi2_log(instance, fmi2Error, "%s: a step from t = %.17g s over %.17g s: t must be finite and the communication "
             "step size finite and positive; the instance unchanged", call, t, h);
    return 0;
}
