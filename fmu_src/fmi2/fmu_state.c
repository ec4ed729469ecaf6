/* fmu_state.c: FMU states and their serialisation (fmu_state.h). */
#include "fmu_state.h"

#include <stdlib.h>
#include <string.h>

#include "instance.h"

#define STATE_TAG "fmi2 state of the attitude-fmu plumbing" /* what a saved state starts with */
#define TAG_SIZE 48
#define FORMAT_VERSION 1u
#define GUID_SIZE 64

typedef struct {
    char tag[TAG_SIZE];        /* STATE_TAG */
    unsigned version;          /* FORMAT_VERSION */
    int phase;                 /* the instance's state in the state machine */
    char guid[GUID_SIZE];      /* the model's guid */
    unsigned long long size;   /* bytes of data */
    unsigned long long check;  /* FNV-1a of the data */
} Header;

/* an FMU state: the header, then the data block */
typedef struct {
    Header header;
    unsigned char data[];
} State;

static unsigned long long checksum(const unsigned char *data, size_t size) {
    unsigned long long h = 14695981039346656037ull;
    for (size_t i = 0; i < size; i++) {
        h ^= data[i];
        h *= 1099511628211ull;
    }
    return h;
}

static void header_of(const Fmi2Instance *instance, Header *header) {
    memset(header, 0, sizeof *header);
    strncpy(header->tag, STATE_TAG, TAG_SIZE - 1);
    header->version = FORMAT_VERSION;
    header->phase = instance->phase;
    strncpy(header->guid, fmi2_model.guid, GUID_SIZE - 1);
    header->size = instance->data_size;
    header->check = checksum(instance->data, instance->data_size);
}

/* NULL if header describes a state of this FMU holding size bytes of data, else why not */
static const char *refusal(const Fmi2Instance *instance, const Header *header) {
    if (strncmp(header->tag, STATE_TAG, TAG_SIZE) != 0) return "not an FMU state of this FMU";
    if (header->version != FORMAT_VERSION) return "an FMU state of another version of this FMU's plumbing";
    if (strncmp(header->guid, fmi2_model.guid, GUID_SIZE) != 0) return "an FMU state of another FMU (guid)";
    if (header->size != instance->data_size) return "an FMU state of another size";
    if (header->phase < 0 || header->phase >= FMI2_N_PHASES) return "an FMU state in no known state";
    return NULL;
}

fmi2Status fmi2_get_state(Fmi2Instance *instance, fmi2FMUstate *state) {
    if (!state) {
        fmi2_log(instance, fmi2Error, "fmi2GetFMUstate: NULL FMUstate pointer");
        return fmi2Error;
    }
    State *s = *state; /* reused where the importer hands back a state of this FMU */
    if (!s || refusal(instance, &s->header)) {
        s = malloc(sizeof *s + instance->data_size);
        if (!s) {
            fmi2_log(instance, fmi2Error, "fmi2GetFMUstate: out of memory");
            return fmi2Error;
        }
    }
    header_of(instance, &s->header);
    memcpy(s->data, instance->data, instance->data_size);
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2_set_state(Fmi2Instance *instance, fmi2FMUstate state) {
    const State *s = state;
    const char *why = s ? refusal(instance, &s->header) : "NULL";
    if (!why && s->header.check != checksum(s->data, instance->data_size)) why = "an FMU state whose data changed";
    if (why) {
        fmi2_log(instance, fmi2Error, "fmi2SetFMUstate: %s; state unchanged", why);
        return fmi2Error;
    }
    memcpy(instance->data, s->data, instance->data_size);
    instance->phase = s->header.phase;
    return fmi2OK;
}

fmi2Status fmi2_free_state(Fmi2Instance *instance, fmi2FMUstate *state) {
    if (!state || !*state) return fmi2OK;
    State *s = *state;
    if (refusal(instance, &s->header)) {
        fmi2_log(instance, fmi2Error, "fmi2FreeFMUstate: not an FMU state of this FMU; not freed");
        return fmi2Error;
    }
    memset(&s->header, 0, sizeof s->header); /* a state freed twice is refused, not freed again */
    free(s);
    *state = NULL;
    return fmi2OK;
}

fmi2Status fmi2_serialized_size(Fmi2Instance *instance, fmi2FMUstate state, size_t *size) {
    const State *s = state;
    if (!s || !size || refusal(instance, &s->header)) {
        fmi2_log(instance, fmi2Error, "fmi2SerializedFMUstateSize: not an FMU state of this FMU");
        return fmi2Error;
    }
    *size = sizeof(Header) + instance->data_size;
    return fmi2OK;
}

fmi2Status fmi2_serialize(Fmi2Instance *instance, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    const State *s = state;
    if (!s || refusal(instance, &s->header)) {
        fmi2_log(instance, fmi2Error, "fmi2SerializeFMUstate: not an FMU state of this FMU");
        return fmi2Error;
    }
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
    Header header;
    const char *why = NULL;
    if (!bytes || !state) why = "NULL bytes or FMUstate pointer";
    else if (size != sizeof header + instance->data_size) why = "bytes of another size than this FMU's states";
    if (!why) {
        memcpy(&header, bytes, sizeof header);
        why = refusal(instance, &header);
        if (!why && header.check != checksum((const unsigned char *)bytes + sizeof header, instance->data_size))
            why = "bytes whose data this FMU did not write (checksum)";
    }
    if (why) {
        fmi2_log(instance, fmi2Error, "fmi2DeSerializeFMUstate: %s; no state made", why);
        return fmi2Error;
    }
    State *s = malloc(sizeof *s + instance->data_size);
    if (!s) {
        fmi2_log(instance, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
        return fmi2Error;
    }
    s->header = header;
    memcpy(s->data, bytes + sizeof header, instance->data_size);
    *state = s;
    return fmi2OK;
}
