/* fmu_state.c: FMU states and their serialisation (fmu_state.h). */
#include "fmu_state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"

#define STATE_TAG "fmi2 state of the attitude-fmu plumbing" /* what a saved state starts with */
#define FORMAT_VERSION 2u
#define GUID_SIZE FMI2_STATE_GUID_SIZE
#define REASON_SIZE 1024
#define FNV_BASIS 14695981039346656037ull

typedef Fmi2StateHeader Header;

/* an FMU state: the header, then the data block */
typedef struct {
    Header header;
    unsigned char data[];
} State;

static unsigned long long fnv(unsigned long long h, const void *bytes, size_t size) {
    const unsigned char *data = bytes;
    for (size_t i = 0; i < size; i++) {
        h ^= data[i];
        h *= 1099511628211ull;
    }
    return h;
}

unsigned long long fmi2_state_checksum(const unsigned char *data, size_t size) { return fnv(FNV_BASIS, data, size); }

unsigned long long fmi2_state_configuration(const Fmi2Instance *instance) {
    unsigned long long h = FNV_BASIS;
    for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        if (v->causality != FMI2_PARAMETER) continue;
        switch (v->type) {
        case FMI2_REAL: h = fnv(h, &instance->reals[v->index], sizeof(fmi2Real)); break;
        case FMI2_INTEGER:
        case FMI2_ENUMERATION: h = fnv(h, &instance->integers[v->index], sizeof(fmi2Integer)); break;
        case FMI2_BOOLEAN: h = fnv(h, &instance->booleans[v->index], sizeof(fmi2Boolean)); break;
        case FMI2_STRING: {
            const char *text = instance->strings[v->index], *end = memchr(text, '\0', FMI2_STRING_SIZE);
            h = fnv(h, text, end ? (size_t)(end - text) + 1 : FMI2_STRING_SIZE);
            break;
        }
        }
    }
    return h;
}

/* NULL where every value of the view is one its variable can hold, else why not */
static const char *values_refusal(const Fmi2Instance *view) {
    for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        switch (v->type) {
        case FMI2_ENUMERATION: {
            fmi2Integer value = view->integers[v->index];
            if (value < 1 || (size_t)value > v->n_items) return "an Enumeration's value is none of its items";
            break;
        }
        case FMI2_BOOLEAN:
            if (view->booleans[v->index] != fmi2False && view->booleans[v->index] != fmi2True)
                return "a Boolean's value is neither 0 nor 1";
            break;
        case FMI2_STRING:
            if (!memchr(view->strings[v->index], '\0', FMI2_STRING_SIZE)) return "a String's value has no end";
            break;
        case FMI2_REAL: /* the models' steps leave their outputs as they were rather than not finite */
            if (v->causality == FMI2_OUTPUT && !isfinite(view->reals[v->index]))
                return "an output's value is not finite";
            break;
        default: break;
        }
    }
    return NULL;
}

static int all_zero(const unsigned char *bytes, size_t size) {
    for (size_t i = 0; i < size; i++)
        if (bytes[i]) return 0;
    return 1;
}

/* 0 where the model's state in view is one the model can run in phase, else -1 with the reason: all zero
 * before initialisation (as fmi2Reset leaves it), else what the model's validate accepts against the state
 * its initialise makes from the view's parameters */
static int model_check(const Fmi2Instance *view, int phase, char *reason, size_t size) {
    if (fmi2_model.state_size == 0) return 0;
    int zero = all_zero(view->state, fmi2_model.state_size);
    if (phase == FMI2_INSTANTIATED || phase == FMI2_INITIALIZATION_MODE || (phase == FMI2_ERROR && zero)) {
        if (zero) return 0;
        strncpy(reason, "the model's state of an instance not initialised is not empty", size - 1);
        return -1;
    }
    Fmi2Instance scratch;
    int result = -1;
    if (fmi2_scratch(view, &scratch) < fmi2Error) result = fmi2_model.validate(view->state, scratch.state, reason, size);
    else strncpy(reason, scratch.data ? "the model refuses its parameters" : "out of memory", size - 1);
    free(scratch.data);
    return result;
}

/* 0 where s is a state this FMU wrote and can take, else -1 with the reason (REASON_SIZE bytes); with
 * configured (an initialised instance), a state of its configuration only */
static int state_check(const State *s, const Fmi2Instance *configured, char *reason) {
    const Header *h = &s->header;
    const char *why = NULL;
    Fmi2Instance view;
    memset(reason, 0, REASON_SIZE);
    memset(&view, 0, sizeof view);
    fmi2_instance_bind(&view, (unsigned char *)s->data);
    if (memcmp(h->tag, STATE_TAG, sizeof STATE_TAG) != 0) why = "not an FMU state of this FMU";
    else if (h->version != FORMAT_VERSION) why = "an FMU state of another version of this FMU's plumbing";
    else if (memchr(h->guid, '\0', GUID_SIZE) == NULL || strcmp(h->guid, fmi2_model.guid) != 0)
        why = "an FMU state of another FMU (guid)";
    else if (h->size != view.data_size) why = "an FMU state of another size";
    else if (h->phase < 0 || h->phase >= FMI2_N_PHASES) why = "an FMU state in no known state";
    else if (!isfinite(h->time)) why = "an FMU state whose time is not finite";
    else if (h->check != fmi2_state_checksum(s->data, view.data_size))
        why = "an FMU state whose data changed (checksum)";
    else why = values_refusal(&view); /* before the configuration: its hash reads the values */
    if (!why && h->configuration != fmi2_state_configuration(&view))
        why = "an FMU state whose configuration is not that of its parameters";
    if (!why && configured && h->configuration != fmi2_state_configuration(configured))
        why = "an FMU state of another configuration (parameters other than this instance's)";
    if (why) {
        strncpy(reason, why, REASON_SIZE - 1);
        return -1;
    }
    return model_check(&view, h->phase, reason, REASON_SIZE);
}

/* the place of state in the instance's list, or n_states where it is none of its own */
static size_t place_of(const Fmi2Instance *instance, const void *state) {
    size_t k = 0;
    while (k < instance->n_states && instance->states[k] != state) k++;
    return k;
}

static int own(const Fmi2Instance *instance, const void *state) {
    return state && place_of(instance, state) < instance->n_states;
}

/* a new state with size bytes of data, in the instance's list; NULL where out of memory */
static State *new_state(Fmi2Instance *instance) {
    if (instance->n_states == instance->states_capacity) {
        size_t capacity = instance->states_capacity ? 2 * instance->states_capacity : 4;
        void **states = capacity < ((size_t)-1) / sizeof *states ? realloc(instance->states, capacity * sizeof *states)
                                                                 : NULL;
        if (!states) return NULL;
        instance->states = states;
        instance->states_capacity = capacity;
    }
    State *s = malloc(sizeof *s + instance->data_size);
    if (s) instance->states[instance->n_states++] = s;
    return s;
}

static void drop_state(Fmi2Instance *instance, State *s) {
    size_t k = place_of(instance, s);
    if (k == instance->n_states) return;
    instance->states[k] = instance->states[--instance->n_states];
    free(s);
}

void fmi2_free_states(Fmi2Instance *instance) {
    for (size_t k = 0; k < instance->n_states; k++) free(instance->states[k]);
    free(instance->states);
    instance->states = NULL;
    instance->n_states = instance->states_capacity = 0;
}

static int refuse_foreign(Fmi2Instance *instance, const char *call, const void *state) {
    if (own(instance, state)) return 0;
    fmi2_log(instance, fmi2Error, "%s: %s", call,
             state ? "not an FMU state of this instance (freed already, or another's); untouched" : "NULL FMU state");
    return 1;
}

fmi2Status fmi2_get_state(Fmi2Instance *instance, fmi2FMUstate *state) {
    if (!state) {
        fmi2_log(instance, fmi2Error, "fmi2GetFMUstate: NULL FMUstate pointer");
        return fmi2Error;
    }
    State *s = *state; /* a state of this instance is overwritten */
    if (s && refuse_foreign(instance, "fmi2GetFMUstate", s)) return fmi2Error;
    if (!s && !(s = new_state(instance))) {
        fmi2_log(instance, fmi2Error, "fmi2GetFMUstate: out of memory");
        return fmi2Error;
    }
    Header *h = &s->header;
    memset(h, 0, sizeof *h);
    memcpy(h->tag, STATE_TAG, sizeof STATE_TAG);
    h->version = FORMAT_VERSION;
    h->phase = instance->phase;
    strncpy(h->guid, fmi2_model.guid, GUID_SIZE - 1);
    h->size = instance->data_size;
    h->configuration = fmi2_state_configuration(instance);
    h->time = instance->time;
    h->check = fmi2_state_checksum(instance->data, instance->data_size);
    memcpy(s->data, instance->data, instance->data_size);
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2_set_state(Fmi2Instance *instance, fmi2FMUstate state) {
    if (refuse_foreign(instance, "fmi2SetFMUstate", state)) return fmi2Error;
    const State *s = state;
    char reason[REASON_SIZE];
    int configured = instance->phase == FMI2_STEP_COMPLETE || instance->phase == FMI2_TERMINATED;
    if (state_check(s, configured ? instance : NULL, reason) != 0) {
        fmi2_log(instance, fmi2Error, "fmi2SetFMUstate: %s; the instance unchanged", reason);
        return fmi2Error;
    }
    memcpy(instance->data, s->data, instance->data_size);
    instance->phase = s->header.phase;
    instance->time = s->header.time;
    return fmi2OK;
}

fmi2Status fmi2_free_state(Fmi2Instance *instance, fmi2FMUstate *state) {
    if (!state || !*state) return fmi2OK;
    if (refuse_foreign(instance, "fmi2FreeFMUstate", *state)) return fmi2Error;
    drop_state(instance, *state);
    *state = NULL;
    return fmi2OK;
}

fmi2Status fmi2_serialized_size(Fmi2Instance *instance, fmi2FMUstate state, size_t *size) {
    if (refuse_foreign(instance, "fmi2SerializedFMUstateSize", state)) return fmi2Error;
    if (!size) {
        fmi2_log(instance, fmi2Error, "fmi2SerializedFMUstateSize: NULL size pointer");
        return fmi2Error;
    }
    *size = sizeof(Header) + instance->data_size;
    return fmi2OK;
}

fmi2Status fmi2_serialize(Fmi2Instance *instance, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    if (refuse_foreign(instance, "fmi2SerializeFMUstate", state)) return fmi2Error;
    const State *s = state;
    if (!bytes || size != sizeof(Header) + instance->data_size) {
        fmi2_log(instance, fmi2Error, "fmi2SerializeFMUstate: %lu bytes given, the state takes %lu",
                 (unsigned long)size, (unsigned long)(sizeof(Header) + instance->data_size));
        return fmi2Error;
    }
    memcpy(bytes, &s->header, sizeof s->header);
    memcpy(bytes + sizeof s->header, s->data, instance->data_size);
    return fmi2OK;
}

fmi2Status fmi2_deserialize(Fmi2Instance *instance, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    char reason[REASON_SIZE] = "";
    if (!bytes || !state) strncpy(reason, "NULL bytes or FMUstate pointer", sizeof reason - 1);
    else if (size != sizeof(Header) + instance->data_size)
        strncpy(reason, "bytes of another size than this FMU's states", sizeof reason - 1);
    if (reason[0]) {
        fmi2_log(instance, fmi2Error, "fmi2DeSerializeFMUstate: %s; no state made", reason);
        return fmi2Error;
    }
    State *s = new_state(instance);
    if (!s) {
        fmi2_log(instance, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
        return fmi2Error;
    }
    memcpy(&s->header, bytes, sizeof s->header);
    memcpy(s->data, bytes + sizeof s->header, instance->data_size);
    if (state_check(s, NULL, reason) != 0) {
        drop_state(instance, s);
        fmi2_log(instance, fmi2Error, "fmi2DeSerializeFMUstate: %s; no state made", reason);
        return fmi2Error;
    }
    *state = s;
    return fmi2OK;
}
