/* instance.h: an FMU instance of the plumbing: its life (instantiate, reset, free), the FMI 2.0
 * co-simulation state machine and the logging through the importer's callback. */
#ifndef FMI2_INSTANCE_H
#define FMI2_INSTANCE_H

#include "fmi2_model.h"

/* The states of the FMI 2.0 co-simulation state machine this plumbing goes through (steps are
 * synchronous: none is ever in progress, failed or cancelled). Any call that returns fmi2Error
 * leaves the instance in FMI2_ERROR, from which fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance
 * lead on. */
typedef enum {
    FMI2_INSTANTIATED,
    FMI2_INITIALIZATION_MODE,
    FMI2_STEP_COMPLETE,
    FMI2_TERMINATED,
    FMI2_ERROR,
    FMI2_N_PHASES
} Fmi2Phase;

#define FMI2_IN(phase) (1u << (phase))
#define FMI2_ANY_PHASE ((1u << FMI2_N_PHASES) - 1u)

/* A new instance with its values at their start values, or NULL (logged through functions). */
Fmi2Instance *fmi2_instance_new(fmi2String name, const fmi2CallbackFunctions *functions, fmi2Boolean logging_on);
void fmi2_instance_free(Fmi2Instance *instance);
/* The bytes of an instance's data block (its values and the model's state). */
size_t fmi2_data_size(void);
/* instance's data and its values' and the model's state's places within it: data, fmi2_data_size() bytes
 * (an FMU state's, to read as an instance's). */
void fmi2_instance_bind(Fmi2Instance *instance, unsigned char *data);
/* Back to FMI2_INSTANTIATED: start values, the model's state zero. */
void fmi2_instance_reset(Fmi2Instance *instance);

/* scratch: a copy of view's values (its own data block, which the caller frees: free(scratch->data), NULL where
 * it could not be had), with no logger, in Initialization Mode at view's start time, initialised by the model
 * from them: the model's initialise's status (fmi2Error where memory ran out). */
fmi2Status fmi2_scratch(const Fmi2Instance *view, Fmi2Instance *scratch);
/* fmi2ExitInitializationMode's and fmi3ExitInitializationMode's work: the model initialised from the
 * parameters, then the outputs at the start time (Fmi2Model.start); step mode unless it refused. */
fmi2Status fmi2_initialise(Fmi2Instance *instance);
/* A get in Initialization Mode: the calculated outputs at the start time from the values as they are
 * (Fmi2Model.start on a scratch copy); where the model refuses its parameters they keep their values,
 * and fmi2ExitInitializationMode says why. */
void fmi2_start_outputs(Fmi2Instance *instance);

/* The start of a call: 1 if the instance's state allows it (allowed: FMI2_IN bits), else 0 with
 * an error logged and the instance in FMI2_ERROR. Traces the call (category logCalls). */
int fmi2_enter(Fmi2Instance *instance, const char *call, unsigned allowed);
/* The end of a call: status raised to what the call logged; fmi2Error or worse leaves the
 * instance in FMI2_ERROR. */
fmi2Status fmi2_leave(Fmi2Instance *instance, fmi2Status status);
/* The end of a call that refuses what it is given without harm to the instance (a foreign or forged FMU
 * state): status raised to what the call logged, the instance left in its state. */
fmi2Status fmi2_leave_unchanged(Fmi2Instance *instance, fmi2Status status);

/* Whether a step from t over h (s) can be given to the model: t and h finite, h > 0; else 0 with an error
 * logged. (A step whose end t + h overflows is the model's to refuse, in its words.) */
int fmi2_step_allowed(Fmi2Instance *instance, const char *call, double t, double h);

/* Turn debug logging on or off for the named categories (all for n == 0); an unknown name is
 * logged as a warning. */
void fmi2_set_debug_logging(Fmi2Instance *instance, fmi2Boolean on, size_t n, const fmi2String categories[]);

/* Log through functions before an instance exists (fmi2Instantiate's refusals). */
void fmi2_log_to(const fmi2CallbackFunctions *functions, fmi2String name, fmi2Status status, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

const char *fmi2_phase_name(int phase);

/* Free the FMU states the instance still holds (fmi2FreeInstance). */
void fmi2_free_states(Fmi2Instance *instance);

#endif
