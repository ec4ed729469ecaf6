/* fmu_state.h: FMU states (fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate) and their
 * serialisation: a copy of the instance's state of the state machine and of its data block (the
 * values and the model's plain-data state). Serialised bytes carry a header (a tag, the format's
 * version, the model's guid, the size and a checksum of the data); bytes that do not match this
 * FMU's are refused with fmi2Error. */
#ifndef FMI2_FMU_STATE_H
#define FMI2_FMU_STATE_H

#include "fmi2_model.h"

fmi2Status fmi2_get_state(Fmi2Instance *instance, fmi2FMUstate *state);
fmi2Status fmi2_set_state(Fmi2Instance *instance, fmi2FMUstate state);
fmi2Status fmi2_free_state(Fmi2Instance *instance, fmi2FMUstate *state);
fmi2Status fmi2_serialized_size(Fmi2Instance *instance, fmi2FMUstate state, size_t *size);
fmi2Status fmi2_serialize(Fmi2Instance *instance, fmi2FMUstate state, fmi2Byte bytes[], size_t size);
fmi2Status fmi2_deserialize(Fmi2Instance *instance, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state);

#endif
