/* fmu_state.h: FMU states (fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate) and their
 * serialisation: a copy of the instance's state of the state machine, its time and its data block
 * (the values and the model's plain-data state). Serialised bytes carry a header (a tag, the
 * format's version, the model's guid, the size, the configuration: a hash of the parameters'
 * values, and a checksum of the data). Bytes nobody vouches for: before a state is made of them
 * (fmi2DeSerializeFMUstate) and again before one is taken (fmi2SetFMUstate), the header, every
 * value (an Enumeration's among its items, a Boolean 0 or 1, a String ended) and the model's state
 * (Fmi2Model.validate, against the model initialised from the state's own parameters) are checked;
 * an initialised instance takes states of its own configuration only. A refusal is fmi2Error with
 * the reason, the instance unchanged. An instance keeps the states it made in a list: a state not
 * in it (freed already, another instance's) is refused without being read; those left are freed
 * with the instance. */
#ifndef FMI2_FMU_STATE_H
#define FMI2_FMU_STATE_H

#include "fmi2_model.h"

#define FMI2_STATE_TAG_SIZE 48
#define FMI2_STATE_GUID_SIZE 64

/* The header of an FMU state and of its serialised bytes, the data block after it. */
typedef struct {
    char tag[FMI2_STATE_TAG_SIZE];    /* "fmi2 state of the attitude-fmu plumbing" */
    unsigned version;                 /* the format's */
    int phase;                        /* the instance's state in the state machine (Fmi2Phase) */
    char guid[FMI2_STATE_GUID_SIZE];  /* the model's guid (FMI 3.0: its instantiation token) */
    unsigned long long size;          /* bytes of data */
    unsigned long long configuration; /* fmi2_state_configuration: the configuration it belongs to */
    double time;                      /* the instance's time (FMI 3.0's `time`), s */
    unsigned long long check;         /* fmi2_state_checksum of the data: against corruption, no defence */
} Fmi2StateHeader;

/* What a header holds of its data, which anyone can compute (so nothing is taken on their word): the
 * configuration, FNV-1a of the values of the instance's (or a view's over a state's data) parameters,
 * and the checksum, FNV-1a of size bytes of data. */
unsigned long long fmi2_state_configuration(const Fmi2Instance *instance);
unsigned long long fmi2_state_checksum(const unsigned char *data, size_t size);

fmi2Status fmi2_get_state(Fmi2Instance *instance, fmi2FMUstate *state);
fmi2Status fmi2_set_state(Fmi2Instance *instance, fmi2FMUstate state);
fmi2Status fmi2_free_state(Fmi2Instance *instance, fmi2FMUstate *state);
fmi2Status fmi2_serialized_size(Fmi2Instance *instance, fmi2FMUstate state, size_t *size);
fmi2Status fmi2_serialize(Fmi2Instance *instance, fmi2FMUstate state, fmi2Byte bytes[], size_t size);
fmi2Status fmi2_deserialize(Fmi2Instance *instance, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state);

#endif
