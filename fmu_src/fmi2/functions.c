/* functions.c: the FMI 2.0 co-simulation entry points (fmi2Functions.h). Each checks that the
 * instance's state allows the call (instance.h: fmi2_enter), does it, and returns the status the
 * standard gives it, raised to what the call logged (fmi2_leave). A call without an instance
 * (NULL) returns fmi2Error: there is no logger to tell. */
#include <math.h>
#include <string.h>

#include "fmi2_model.h"
#include "fmu_state.h"
#include "instance.h"
#include "values.h"

#define BEFORE_INITIALISED (FMI2_IN(FMI2_INSTANTIATED) | FMI2_IN(FMI2_INITIALIZATION_MODE))
#define INITIALISED FMI2_IN(FMI2_STEP_COMPLETE)
#define ONCE_INITIALISING (FMI2_IN(FMI2_INITIALIZATION_MODE) | INITIALISED | FMI2_IN(FMI2_TERMINATED) | \
                           FMI2_IN(FMI2_ERROR))
#define GETTABLE ONCE_INITIALISING
#define SETTABLE (BEFORE_INITIALISED | INITIALISED)
#define STEPPED (INITIALISED | FMI2_IN(FMI2_TERMINATED))

/* the instance of c, or return fmi2Error from the calling function */
#define INSTANCE(c, call, allowed)                                                                                 \
    Fmi2Instance *instance = (Fmi2Instance *)(c);                                                                 \
    if (!instance) return fmi2Error;                                                                               \
    if (!fmi2_enter(instance, call, allowed)) return fmi2Error

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; /* the model needs no resources: any location will do, or none */
    (void)visible;
    if (!functions) return NULL;
    if (fmuType != fmi2CoSimulation) {
        fmi2_log_to(functions, instanceName, fmi2Error, "fmi2Instantiate: %s is an FMU for co-simulation only",
                    fmi2_model.identifier);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, fmi2_model.guid) != 0) {
        fmi2_log_to(functions, instanceName, fmi2Error,
                    "fmi2Instantiate: guid %s is not this binary's, %s: its modelDescription.xml is another FMU's",
                    fmuGUID ? fmuGUID : "(null)", fmi2_model.guid);
        return NULL;
    }
    return fmi2_instance_new(instanceName, functions, loggingOn);
}

void fmi2FreeInstance(fmi2Component c) { /* with the FMU states it still holds */
    if (c) fmi2_instance_free((Fmi2Instance *)c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    INSTANCE(c, "fmi2SetDebugLogging", FMI2_ANY_PHASE);
    fmi2_set_debug_logging(instance, loggingOn, nCategories, categories);
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    INSTANCE(c, "fmi2SetupExperiment", FMI2_IN(FMI2_INSTANTIATED));
    if (!isfinite(startTime)) {
        fmi2_log(instance, fmi2Error, "fmi2SetupExperiment: the start time %g s is not finite", startTime);
        return fmi2_leave(instance, fmi2Error);
    }
    instance->start_time = startTime;
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    INSTANCE(c, "fmi2EnterInitializationMode", FMI2_IN(FMI2_INSTANTIATED));
    instance->phase = FMI2_INITIALIZATION_MODE;
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    INSTANCE(c, "fmi2ExitInitializationMode", FMI2_IN(FMI2_INITIALIZATION_MODE));
    return fmi2_leave(instance, fmi2_initialise(instance));
}

fmi2Status fmi2Terminate(fmi2Component c) {
    INSTANCE(c, "fmi2Terminate", INITIALISED);
    instance->phase = FMI2_TERMINATED;
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2Reset(fmi2Component c) {
    INSTANCE(c, "fmi2Reset", FMI2_ANY_PHASE);
    fmi2_instance_reset(instance);
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE(c, "fmi2DoStep", INITIALISED);
    if (!fmi2_step_allowed(instance, "fmi2DoStep", currentCommunicationPoint, communicationStepSize))
        return fmi2_leave(instance, fmi2Error);
    return fmi2_leave(instance, fmi2_model.step(instance, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    INSTANCE(c, "fmi2CancelStep", FMI2_ANY_PHASE);
    fmi2_log(instance, fmi2Error, "fmi2CancelStep: no step is in progress (fmi2DoStep returns when it is done)");
    return fmi2_leave(instance, fmi2Error);
}

/* fmi2Get* and fmi2Set* of each type */
#define GET_SET(Type, TYPES, type)                                                                                 \
    fmi2Status fmi2Get##Type(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, type value[]) {            \
        INSTANCE(c, "fmi2Get" #Type, GETTABLE);                                                                    \
        return fmi2_leave(instance, fmi2_get_values(instance, "fmi2Get" #Type, TYPES, vr, nvr, value));            \
    }                                                                                                              \
    fmi2Status fmi2Set##Type(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const type value[]) {      \
        INSTANCE(c, "fmi2Set" #Type, SETTABLE);                                                                    \
        return fmi2_leave(instance, fmi2_set_values(instance, "fmi2Set" #Type, TYPES, vr, nvr, value));            \
    }
GET_SET(Real, FMI2_TYPES(FMI2_REAL), fmi2Real)
GET_SET(Integer, FMI2_INTEGERS, fmi2Integer)
GET_SET(Boolean, FMI2_TYPES(FMI2_BOOLEAN), fmi2Boolean)
GET_SET(String, FMI2_TYPES(FMI2_STRING), fmi2String)
#undef GET_SET

/* FMU states: a refused one (foreign, freed, forged) is fmi2Error with the instance as it was, its state in
 * the state machine too (fmi2_leave_unchanged) */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    INSTANCE(c, "fmi2GetFMUstate", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance, fmi2_get_state(instance, FMUstate));
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    INSTANCE(c, "fmi2SetFMUstate", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance, fmi2_set_state(instance, FMUstate));
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    INSTANCE(c, "fmi2FreeFMUstate", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance, fmi2_free_state(instance, FMUstate));
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    INSTANCE(c, "fmi2SerializedFMUstateSize", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance, fmi2_serialized_size(instance, FMUstate, size));
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size) {
    INSTANCE(c, "fmi2SerializeFMUstate", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance, fmi2_serialize(instance, FMUstate, serializedState, size));
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    INSTANCE(c, "fmi2DeSerializeFMUstate", FMI2_ANY_PHASE);
    return fmi2_leave_unchanged(instance,
                                fmi2_deserialize(instance, serializedState, size, FMUstate));
}

/* what the model description says this FMU does not provide */
static fmi2Status unsupported(fmi2Component c, const char *call, const char *why) {
    INSTANCE(c, call, FMI2_ANY_PHASE);
    fmi2_log(instance, fmi2Error, "%s: %s", call, why);
    return fmi2_leave(instance, fmi2Error);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    return unsupported(c, "fmi2GetDirectionalDerivative", "not provided (providesDirectionalDerivative=\"false\")");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives", "inputs are not interpolated (canInterpolateInputs=\"false\")");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives", "none provided (maxOutputDerivativeOrder=\"0\")");
}

/* the asynchronous step's status: steps here are synchronous, so only "terminated" has an answer (no) */
static fmi2Status no_status(fmi2Component c, const char *call) {
    INSTANCE(c, call, STEPPED);
    fmi2_log(instance, fmi2Discard, "%s: steps are synchronous; there is no such status to report", call);
    return fmi2_leave(instance, fmi2Discard);
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetStatus");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetRealStatus");
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    if (s != fmi2Terminated || !value) return no_status(c, "fmi2GetBooleanStatus");
    INSTANCE(c, "fmi2GetBooleanStatus", STEPPED);
    *value = fmi2False; /* the model never asks to end the simulation */
    return fmi2_leave(instance, fmi2OK);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetStringStatus");
}
