/* NoOpEstimator.c: AttitudeEstimator's interface with nothing behind it, the baseline of the FMU
 * benchmark (attitude bench --fmu): what the FMI plumbing alone costs per step.
 * Python twin: fmu_src/NoOpEstimator.py. */
#include "NoOpEstimator_variables.h"

static fmi2Status initialise(Fmi2Instance *instance) {
    (void)instance;
    return fmi2OK;
}

static int validate(const void *state, const void *configured, char *message, size_t size) {
    (void)state, (void)configured, (void)message, (void)size;
    return 0; /* no state of its own */
}

static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h) {
    (void)instance, (void)t, (void)h;
    return fmi2OK;
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, 0, initialise, step, validate, NULL,
};
