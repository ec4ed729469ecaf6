/* functions.c: the FMI 3.0 entry points (fmi3Functions.h) of a co-simulation FMU without event
 * mode, clocks or intermediate updates. Each checks that the instance's state allows the call
 * (fmi2/instance.h: the states Instantiated, Initialization Mode, Step Mode (there "step
 * complete"), Terminated and the error state), does it through the plumbing, and returns the status
 * the standard gives it, raised to what the call logged. A call without an instance (NULL) returns
 * fmi3Error: there is no logger to tell. The variables are the model's (Float64, Int32, Int64, Boolean and
 * String: its Real, Integer, Enumeration, Boolean and String ones; a Float64 array holds its elements'
 * values, Fmi2Variable.fmi3_count) and `time`, the independent variable. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2/fmu_state.h"
#include "fmi2/instance.h"
#include "fmi2/values.h"
#include "instance3.h"

#define BEFORE_INITIALISED (FMI2_IN(FMI2_INSTANTIATED) | FMI2_IN(FMI2_INITIALIZATION_MODE))
#define STEP_MODE FMI2_IN(FMI2_STEP_COMPLETE)
#define GETTABLE (FMI2_IN(FMI2_INITIALIZATION_MODE) | STEP_MODE | FMI2_IN(FMI2_TERMINATED) | FMI2_IN(FMI2_ERROR))
#define SETTABLE (BEFORE_INITIALISED | STEP_MODE)

/* the instance of c, or return fmi3Error from the calling function */
#define INSTANCE(c, call, allowed)                                                                                 \
    Fmi2Instance *instance = (Fmi2Instance *)(c);                                                                 \
    if (!instance) return fmi3Error;                                                                               \
    if (!fmi2_enter(instance, call, allowed)) return fmi3Error

/* the most value references a call takes (a variable's may repeat): far more than any importer passes, so
 * that no count overflows what is sized by it */
#define MAX_COUNT ((size_t)1 << 24)

static fmi3Status leave(Fmi2Instance *instance, fmi2Status status) { return (fmi3Status)fmi2_leave(instance, status); }

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    INSTANCE(c, "fmi3SetDebugLogging", FMI2_ANY_PHASE);
    fmi2_set_debug_logging(instance, loggingOn ? fmi2True : fmi2False, nCategories, categories);
    return leave(instance, fmi2OK);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    /* the model needs no resources; steps never return early; no intermediate variables are offered */
    (void)resourcePath, (void)visible, (void)earlyReturnAllowed, (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables, (void)intermediateUpdate;
    if (eventModeUsed) {
        fmi3_log_to(instanceEnvironment, logMessage, instanceName, fmi3Error,
                    "fmi3InstantiateCoSimulation: this FMU has no event mode (hasEventMode=\"false\")");
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, fmi2_model.guid) != 0) {
        fmi3_log_to(instanceEnvironment, logMessage, instanceName, fmi3Error,
                    "fmi3InstantiateCoSimulation: the instantiation token is not this binary's: its "
                    "modelDescription.xml is another FMU's");
        return NULL;
    }
    return fmi3_instance_new(instanceName, loggingOn, instanceEnvironment, logMessage);
}

/* the interface types this FMU is not instantiated as */
fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    fmi3_log_to(instanceEnvironment, logMessage, instanceName, fmi3Error,
                "fmi3InstantiateModelExchange: this is an FMU for co-simulation only");
    return NULL;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn, (void)clockUpdate;
    (void)lockPreemption, (void)unlockPreemption;
    fmi3_log_to(instanceEnvironment, logMessage, instanceName, fmi3Error,
                "fmi3InstantiateScheduledExecution: this is an FMU for co-simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance c) {
    if (c) fmi3_instance_free((Fmi2Instance *)c);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    INSTANCE(c, "fmi3EnterInitializationMode", FMI2_IN(FMI2_INSTANTIATED));
    if (!isfinite(startTime)) {
        fmi2_log(instance, fmi2Error, "fmi3EnterInitializationMode: the start time %g s is not finite", startTime);
        return leave(instance, fmi2Error);
    }
    instance->time = instance->start_time = startTime;
    instance->phase = FMI2_INITIALIZATION_MODE;
    return leave(instance, fmi2OK);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c) {
    INSTANCE(c, "fmi3ExitInitializationMode", FMI2_IN(FMI2_INITIALIZATION_MODE));
    return leave(instance, fmi2_initialise(instance));
}

fmi3Status fmi3Terminate(fmi3Instance c) {
    INSTANCE(c, "fmi3Terminate", STEP_MODE);
    instance->phase = FMI2_TERMINATED;
    return leave(instance, fmi2OK);
}

fmi3Status fmi3Reset(fmi3Instance c) {
    INSTANCE(c, "fmi3Reset", FMI2_ANY_PHASE);
    fmi2_instance_reset(instance);
    return leave(instance, fmi2OK);
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE(c, "fmi3DoStep", STEP_MODE);
    if (eventHandlingNeeded) *eventHandlingNeeded = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (earlyReturn) *earlyReturn = false;
    if (lastSuccessfulTime) *lastSuccessfulTime = currentCommunicationPoint;
    if (!fmi2_step_allowed(instance, "fmi3DoStep", currentCommunicationPoint, communicationStepSize))
        return leave(instance, fmi2Error);
    fmi2Status status = fmi2_model.step(instance, currentCommunicationPoint, communicationStepSize);
    if (status < fmi2Error) {
        instance->time = currentCommunicationPoint + communicationStepSize;
        if (lastSuccessfulTime) *lastSuccessfulTime = instance->time;
    }
    return leave(instance, status);
}

/* whether the call's nvr value references and n_values values (arrays vr, values) can be taken: as many, a
 * count within MAX_COUNT, arrays given; else 0 with the error logged */
static int counts_match(Fmi2Instance *instance, const char *call, size_t nvr, size_t n_values, const void *vr,
                        const void *values) {
    if (nvr == n_values && nvr <= MAX_COUNT && (nvr == 0 || (vr && values))) return 1;
    if (nvr == n_values && nvr <= MAX_COUNT) {
        fmi2_log(instance, fmi2Error, "%s: NULL value references or values for %lu variables", call,
                 (unsigned long)nvr);
        return 0;
    }
    if (nvr == n_values) {
        fmi2_log(instance, fmi2Error, "%s: %lu value references: more than the %lu a call takes", call,
                 (unsigned long)nvr, (unsigned long)MAX_COUNT);
        return 0;
    }
    fmi2_log(instance, fmi2Error, "%s: %lu values for %lu value references (every variable here is a scalar)", call,
             (unsigned long)n_values, (unsigned long)nvr);
    return 0;
}

/* the values of a Float64 value reference: time's 1, a variable's its fmi3_count (an array's elements), 0 for
 * none (refused where it is read) */
static size_t float64_count(fmi3ValueReference vr) {
    if (vr == FMI3_TIME_VR) return 1;
    return vr < fmi2_model.n_variables ? fmi2_model.variables[vr].fmi3_count : 1;
}

/* counts_match for Float64, whose arrays hold several values: n_values the values of the nvr value references
 * together (float64_count), a value reference that is none of a variable's first counting as one, to be
 * refused by name where it is read */
static int float64_counts_match(Fmi2Instance *instance, const char *call, size_t nvr, size_t n_values,
                                const fmi3ValueReference *vr, const void *values) {
    size_t total = 0;
    if (nvr > MAX_COUNT || n_values > MAX_COUNT || (nvr > 0 && !vr))
        return counts_match(instance, call, nvr, n_values, vr, values);
    for (size_t i = 0; i < nvr; i++) {
        size_t count = float64_count(vr[i]);
        total += count ? count : 1;
    }
    if (total == n_values) return counts_match(instance, call, n_values, n_values, vr, values);
    fmi2_log(instance, fmi2Error, "%s: %lu values for %lu value references, which hold %lu", call,
             (unsigned long)n_values, (unsigned long)nvr, (unsigned long)total);
    return 0;
}

/* a value reference that names no FMI 3.0 variable (an array's element other than its first): refused */
static int is_element(Fmi2Instance *instance, const char *call, fmi3ValueReference vr) {
    if (float64_count(vr) != 0) return 0;
    fmi2_log(instance, fmi2Error, "%s: value reference %lu is no variable of this FMU (an element of the array "
             "before it)", call, (unsigned long)vr);
    return 1;
}

fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues) {
    INSTANCE(c, "fmi3GetFloat64", GETTABLE);
    if (!float64_counts_match(instance, "fmi3GetFloat64", nvr, nValues, vr, values))
        return leave(instance, fmi2Error);
    for (size_t i = 0, k = 0; i < nvr; i++) {
        if (vr[i] == FMI3_TIME_VR) {
            values[k++] = instance->time;
            continue;
        }
        if (is_element(instance, "fmi3GetFloat64", vr[i])) return leave(instance, fmi2Error);
        for (size_t e = 0, count = float64_count(vr[i]); e < count; e++, k++) {
            const fmi2ValueReference element = (fmi2ValueReference)(vr[i] + e);
            if (fmi2_get_values(instance, "fmi3GetFloat64", FMI2_TYPES(FMI2_REAL), &element, 1, &values[k]) != fmi2OK)
                return leave(instance, fmi2Error);
        }
    }
    return leave(instance, fmi2OK);
}

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues) {
    INSTANCE(c, "fmi3SetFloat64", SETTABLE);
    if (!float64_counts_match(instance, "fmi3SetFloat64", nvr, nValues, vr, values))
        return leave(instance, fmi2Error);
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == FMI3_TIME_VR) {
            fmi2_log(instance, fmi2Error, "fmi3SetFloat64: time is the independent variable: it cannot be set");
            return leave(instance, fmi2Error);
        }
        if (is_element(instance, "fmi3SetFloat64", vr[i])) return leave(instance, fmi2Error);
    }
    if (nValues == nvr) /* scalars only: one call, every value checked before any is set */
        return leave(instance, fmi2_set_values(instance, "fmi3SetFloat64", FMI2_TYPES(FMI2_REAL), vr, nvr, values));
    /* arrays: their elements' value references, nValues of them, then one call likewise */
    fmi2ValueReference *elements = malloc(nValues * sizeof *elements);
    if (!elements) {
        fmi2_log(instance, fmi2Error, "fmi3SetFloat64: no memory for %lu values", (unsigned long)nValues);
        return leave(instance, fmi2Error);
    }
    for (size_t i = 0, k = 0; i < nvr; i++)
        for (size_t e = 0, count = float64_count(vr[i]); e < count; e++) elements[k++] = (fmi2ValueReference)(vr[i] + e);
    fmi2Status status = fmi2_set_values(instance, "fmi3SetFloat64", FMI2_TYPES(FMI2_REAL), elements, nValues, values);
    free(elements);
    return leave(instance, status);
}

fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                         size_t nValues) {
    INSTANCE(c, "fmi3GetString", GETTABLE);
    if (!counts_match(instance, "fmi3GetString", nvr, nValues, vr, values)) return leave(instance, fmi2Error);
    return leave(instance, fmi2_get_values(instance, "fmi3GetString", FMI2_TYPES(FMI2_STRING), vr, nvr, values));
}

fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3String values[],
                         size_t nValues) {
    INSTANCE(c, "fmi3SetString", SETTABLE);
    if (!counts_match(instance, "fmi3SetString", nvr, nValues, vr, values)) return leave(instance, fmi2Error);
    return leave(instance, fmi2_set_values(instance, "fmi3SetString", FMI2_TYPES(FMI2_STRING), vr, nvr, values));
}

/* Boolean values are held as fmi2Boolean, Int32 (Integer variables) and Int64 (Enumeration variables,
 * as FMI 3.0 sets and gets them) as fmi2Integer: converted one by one on a get, through a copy on a
 * set (which changes none of the values if one is refused; nor does one the held type cannot hold) */
#define CONVERTED(Type, type, TYPES, held)                                                                         \
    fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, type values[],             \
                             size_t nValues) {                                                                     \
        INSTANCE(c, "fmi3Get" #Type, GETTABLE);                                                                    \
        if (!counts_match(instance, "fmi3Get" #Type, nvr, nValues, vr, values))                                    \
            return leave(instance, fmi2Error);                                                                     \
        for (size_t i = 0; i < nvr; i++) {                                                                         \
            held value;                                                                                            \
            if (fmi2_get_values(instance, "fmi3Get" #Type, TYPES, &vr[i], 1, &value) != fmi2OK)                    \
                return leave(instance, fmi2Error);                                                                 \
            values[i] = (type)value;                                                                               \
        }                                                                                                          \
        return leave(instance, fmi2OK);                                                                            \
    }                                                                                                              \
    fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const type values[],       \
                             size_t nValues) {                                                                     \
        INSTANCE(c, "fmi3Set" #Type, SETTABLE);                                                                    \
        if (!counts_match(instance, "fmi3Set" #Type, nvr, nValues, vr, values))                                    \
            return leave(instance, fmi2Error);                                                                     \
        held *copy = malloc((nvr ? nvr : 1) * sizeof *copy);                                                       \
        if (!copy) {                                                                                               \
            fmi2_log(instance, fmi2Error, "fmi3Set" #Type ": out of memory");                                      \
            return leave(instance, fmi2Error);                                                                     \
        }                                                                                                          \
        fmi2Status status = fmi2OK;                                                                                \
        for (size_t i = 0; i < nvr && status == fmi2OK; i++) {                                                     \
            copy[i] = (held)values[i];                                                                             \
            if ((type)copy[i] != values[i]) {                                                                      \
                fmi2_log(instance, fmi2Error, "fmi3Set" #Type ": value %lu is beyond the range of every variable " \
                         "of this type", (unsigned long)i);                                                        \
                status = fmi2Error;                                                                                \
            }                                                                                                      \
        }                                                                                                          \
        if (status == fmi2OK) status = fmi2_set_values(instance, "fmi3Set" #Type, TYPES, vr, nvr, copy);          \
        free(copy);                                                                                                \
        return leave(instance, status);                                                                            \
    }
CONVERTED(Boolean, fmi3Boolean, FMI2_TYPES(FMI2_BOOLEAN), fmi2Boolean)
CONVERTED(Int32, fmi3Int32, FMI2_TYPES(FMI2_INTEGER), fmi2Integer)
CONVERTED(Int64, fmi3Int64, FMI2_TYPES(FMI2_ENUMERATION), fmi2Integer)
#undef CONVERTED

/* the types of which the FMU has no variables: any value reference given is refused */
static fmi3Status no_such_type(fmi3Instance c, const char *call, const fmi3ValueReference vr[], size_t nvr) {
    INSTANCE(c, call, FMI2_ANY_PHASE);
    if (nvr == 0) return leave(instance, fmi2OK);
    if (vr && vr[0] < fmi2_model.n_variables)
        fmi2_log(instance, fmi2Error, "%s: value reference %u is %s, not a variable of this type", call, vr[0],
                 fmi2_model.variables[vr[0]].name);
    else
        fmi2_log(instance, fmi2Error, "%s: this FMU has no variables of this type", call);
    return leave(instance, fmi2Error);
}

#define NO_SUCH_TYPE(Type, type)                                                                                   \
    fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, type values[],             \
                             size_t nValues) {                                                                     \
        (void)values, (void)nValues;                                                                               \
        return no_such_type(c, "fmi3Get" #Type, vr, nvr);                                                          \
    }                                                                                                              \
    fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const type values[],       \
                             size_t nValues) {                                                                     \
        (void)values, (void)nValues;                                                                               \
        return no_such_type(c, "fmi3Set" #Type, vr, nvr);                                                          \
    }
NO_SUCH_TYPE(Float32, fmi3Float32)
NO_SUCH_TYPE(Int8, fmi3Int8)
NO_SUCH_TYPE(UInt8, fmi3UInt8)
NO_SUCH_TYPE(Int16, fmi3Int16)
NO_SUCH_TYPE(UInt16, fmi3UInt16)
NO_SUCH_TYPE(UInt32, fmi3UInt32)
NO_SUCH_TYPE(UInt64, fmi3UInt64)
#undef NO_SUCH_TYPE

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
    (void)valueSizes, (void)values, (void)nValues;
    return no_such_type(c, "fmi3GetBinary", vr, nvr);
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
    (void)valueSizes, (void)values, (void)nValues;
    return no_such_type(c, "fmi3SetBinary", vr, nvr);
}

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[]) {
    (void)values;
    return no_such_type(c, "fmi3GetClock", vr, nvr);
}

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[]) {
    (void)values;
    return no_such_type(c, "fmi3SetClock", vr, nvr);
}

/* FMU states: a refused one is fmi3Error with the instance as it was (fmi2_leave_unchanged) */
fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *FMUState) {
    INSTANCE(c, "fmi3GetFMUState", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(instance, fmi2_get_state(instance, FMUState));
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState FMUState) {
    INSTANCE(c, "fmi3SetFMUState", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(instance, fmi2_set_state(instance, FMUState));
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *FMUState) {
    INSTANCE(c, "fmi3FreeFMUState", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(instance, fmi2_free_state(instance, FMUState));
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState FMUState, size_t *size) {
    INSTANCE(c, "fmi3SerializedFMUStateSize", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(instance, fmi2_serialized_size(instance, FMUState, size));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
    INSTANCE(c, "fmi3SerializeFMUState", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(instance,
                                            fmi2_serialize(instance, FMUState, (fmi2Byte *)serializedState, size));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    INSTANCE(c, "fmi3DeserializeFMUState", FMI2_ANY_PHASE);
    return (fmi3Status)fmi2_leave_unchanged(
        instance, fmi2_deserialize(instance, (const fmi2Byte *)serializedState, size, FMUState));
}

/* what the model description says this FMU does not provide */
static fmi3Status unsupported(fmi3Instance c, const char *call, const char *why) {
    INSTANCE(c, call, FMI2_ANY_PHASE);
    fmi2_log(instance, fmi2Error, "%s: %s", call, why);
    return leave(instance, fmi2Error);
}

#define NO_EVENTS "this FMU has no event mode (hasEventMode=\"false\")"
#define NO_CLOCKS "this FMU has no clocks"
#define CO_SIMULATION "this is an FMU for co-simulation only"

fmi3Status fmi3EnterEventMode(fmi3Instance c) { return unsupported(c, "fmi3EnterEventMode", NO_EVENTS); }
fmi3Status fmi3EnterStepMode(fmi3Instance c) { return unsupported(c, "fmi3EnterStepMode", NO_EVENTS); }
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) {
    return unsupported(c, "fmi3EvaluateDiscreteStates", NO_EVENTS);
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    (void)discreteStatesNeedUpdate, (void)terminateSimulation, (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged, (void)nextEventTimeDefined, (void)nextEventTime;
    return unsupported(c, "fmi3UpdateDiscreteStates", NO_EVENTS);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference, (void)nDependencies;
    return unsupported(c, "fmi3GetNumberOfVariableDependencies", "the model description states no dependencies");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents;
    (void)dependencyKinds, (void)nDependencies;
    return unsupported(c, "fmi3GetVariableDependencies", "the model description states no dependencies");
}

#define NO_DERIVATIVES(name, flag)                                                                                 \
    fmi3Status name(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,                         \
                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,      \
                    fmi3Float64 sensitivity[], size_t nSensitivity) {                                              \
        (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed, (void)sensitivity;  \
        (void)nSensitivity;                                                                                        \
        return unsupported(c, #name, "not provided (" flag "=\"false\")");                                         \
    }
NO_DERIVATIVES(fmi3GetDirectionalDerivative, "providesDirectionalDerivatives")
NO_DERIVATIVES(fmi3GetAdjointDerivative, "providesAdjointDerivatives")
#undef NO_DERIVATIVES

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    (void)vr, (void)nvr, (void)orders, (void)values, (void)nValues;
    return unsupported(c, "fmi3GetOutputDerivatives", "none provided (maxOutputDerivativeOrder=\"0\")");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3EnterConfigurationMode", "this FMU has no structural parameters");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3ExitConfigurationMode", "this FMU has no structural parameters");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    (void)vr, (void)nvr, (void)intervals, (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)vr, (void)nvr, (void)counters, (void)resolutions, (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[]) {
    (void)vr, (void)nvr, (void)shifts;
    return unsupported(c, "fmi3GetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[]) {
    (void)vr, (void)nvr, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3GetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[]) {
    (void)vr, (void)nvr, (void)intervals;
    return unsupported(c, "fmi3SetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr, (void)nvr, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3SetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 shifts[]) {
    (void)vr, (void)nvr, (void)shifts;
    return unsupported(c, "fmi3SetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr, (void)nvr, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3SetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference, fmi3Float64 activationTime) {
    (void)clockReference, (void)activationTime;
    return unsupported(c, "fmi3ActivateModelPartition", CO_SIMULATION);
}

/* Model Exchange's */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) {
    return unsupported(c, "fmi3EnterContinuousTimeMode", CO_SIMULATION);
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    return unsupported(c, "fmi3CompletedIntegratorStep", CO_SIMULATION);
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time) {
    (void)time;
    return unsupported(c, "fmi3SetTime", CO_SIMULATION);
}

#define NO_STATES(name, type)                                                                                      \
    fmi3Status name(fmi3Instance c, type values[], size_t n) {                                                     \
        (void)values, (void)n;                                                                                     \
        return unsupported(c, #name, CO_SIMULATION);                                                               \
    }
NO_STATES(fmi3SetContinuousStates, const fmi3Float64)
NO_STATES(fmi3GetContinuousStateDerivatives, fmi3Float64)
NO_STATES(fmi3GetEventIndicators, fmi3Float64)
NO_STATES(fmi3GetContinuousStates, fmi3Float64)
NO_STATES(fmi3GetNominalsOfContinuousStates, fmi3Float64)
#undef NO_STATES

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators) {
    (void)nEventIndicators;
    return unsupported(c, "fmi3GetNumberOfEventIndicators", CO_SIMULATION);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates) {
    (void)nContinuousStates;
    return unsupported(c, "fmi3GetNumberOfContinuousStates", CO_SIMULATION);
}
