/* AttitudeEstimator.c: the model of the native AttitudeEstimator.fmu: its variables
 * (AttitudeEstimator_variables.h, generated from systems/fmi/interface/variables.py) onto the C core's online
 * estimator (core/pipeline/online.h), on the grid of its sample time Ts from the start time
 * (stages/timing.h: grid_samples): a communication step runs the samples it reaches with its inputs
 * held, one that reaches none (half a sample; a master's final shortfall of picoseconds) holds the
 * estimate, several run in turn.
 * fmu_src/AttitudeEstimator.py is the pythonfmu model of the same variables (the same checks,
 * messages and statuses). */
#include <math.h>
#include <string.h>

#include "AttitudeEstimator_variables.h"
#include "messages.h"
#include "pipeline/online.h"
#include "stages/timing.h"

#define MESSAGE_SIZE 1024

typedef struct {
    AfOnline estimator;
} Model;

static const Fmi2Variable *variable_named(const char *name) {
    for (size_t vr = 0; vr < N_VARIABLES; vr++)
        if (strcmp(MODEL_VARIABLES[vr].name, name) == 0) return &MODEL_VARIABLES[vr];
    return NULL;
}

static fmi2Status initialise(Fmi2Instance *instance) {
    Model *model = instance->state;
    const fmi2Real *r = instance->reals;
    char message[MESSAGE_SIZE], repr[FLOAT_REPR_SIZE];
    if (!(isfinite(r[REAL_Ts]) && r[REAL_Ts] > 0.0)) {
        fmi2_log(instance, fmi2Error, "invalid parameter: Ts must be a finite positive number of seconds, got %s",
                 float_repr(r[REAL_Ts], repr));
        return fmi2Error;
    }
    const char *method = fmi2_item(instance, INTEGER_method), *heading = fmi2_item(instance, INTEGER_heading),
               *gyro_offset = fmi2_item(instance, INTEGER_gyro_offset),
               *gyr_samples = fmi2_item(instance, INTEGER_gyr_samples),
               *acc_samples = fmi2_item(instance, INTEGER_acc_samples);
    if (!method || !heading || !gyro_offset || !gyr_samples || !acc_samples) return fmi2Error;
    AfConfig config = {
        .method = method,
        .heading = strcmp(heading, "mag") == 0,
        .gyro_offset = strcmp(gyro_offset, "on") == 0,
        .latency = r[REAL_latency],
        .gyr_samples = gyr_samples,
        .acc_samples = acc_samples,
    };
    /* given: the tuning parameters whose values differ from their start values (a start or NaN: unset, the
     * default of the stage that runs) */
    for (int k = 0; k < AF_N_PARAMS; k++) {
        const Fmi2Variable *v = variable_named(AF_PARAMS[k].name);
        if (!v || v->type != FMI2_REAL) {
            fmi2_log(instance, fmi2Error, "the tuning parameter %s has no Real variable", AF_PARAMS[k].name);
            return fmi2Error;
        }
        double value = r[v->index];
        config.params[k] = isnan(value) || value == v->start ? NAN : value;
    }
    if (af_online_init(&model->estimator, &config, message, sizeof message) != 0 ||
        af_online_discretise(&model->estimator, r[REAL_Ts], NULL, message, sizeof message) != 0) {
        fmi2_log(instance, fmi2Error, "invalid parameter: %s", message);
        return fmi2Error;
    }
    return fmi2OK;
}

static void put(fmi2Real *to, const double *from, int n) {
    for (int i = 0; i < n; i++) to[i] = from[i];
}

/* whether the estimate's outputs are all finite */
static int outputs_finite(const AfOnline *est) {
    const double *groups[] = {est->quat, est->up, est->euler, est->offset, est->mag_offset, &est->mag_delay};
    const int sizes[] = {4, 3, 3, 3, 3, 1};
    for (int g = 0; g < 6; g++)
        for (int i = 0; i < sizes[g]; i++)
            if (!isfinite(groups[g][i])) return 0;
    return 1;
}

static int validate(const void *state, const void *configured, char *message, size_t size) {
    const Model *model = state;
    return af_online_validate(&model->estimator, &((const Model *)configured)->estimator, message, size);
}

/* one sample of Ts (s) at t (s) on the inputs as they are: fmi2OK with the outputs, fmi2Warning with the
 * estimate held where the inputs are not a sample to take, fmi2Error where the arithmetic fails */
static fmi2Status sample(Fmi2Instance *instance, Model *model, double t) {
    AfOnline *est = &model->estimator;
    fmi2Real *r = instance->reals;
    char message[MESSAGE_SIZE], a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE];
    /* each vector's components are consecutive in the table: x, y, z (w, x, y, z) */
    const double gyr[3] = {r[REAL_gyr_x], r[REAL_gyr_y], r[REAL_gyr_z]};
    const double acc[3] = {r[REAL_acc_x], r[REAL_acc_y], r[REAL_acc_z]};
    const double mag[3] = {r[REAL_mag_x], r[REAL_mag_y], r[REAL_mag_z]};
    int taken = af_online_step(est, gyr, acc, mag, est->step.Ts, message, sizeof message);
    if (taken < 0) {
        fmi2_log(instance, fmi2Error, "%s", message);
        return fmi2Error;
    }
    if (taken == 1 && !outputs_finite(est)) {
        fmi2_log(instance, fmi2Error, "a step of %s s to %s s overflows the estimator's arithmetic; the estimate "
                 "held", float_repr(est->step.Ts, a), float_repr(t + est->step.Ts, b));
        return fmi2Error;
    }
    instance->booleans[BOOLEAN_valid] = taken == 1;
    if (taken == 1) {
        put(&r[REAL_q_w], est->quat, 4);
        put(&r[REAL_g_x], est->up, 3);
        put(&r[REAL_roll], est->euler, 3);
        put(&r[REAL_gyr_offset_x], est->offset, 3);
        put(&r[REAL_mag_offset_x], est->mag_offset, 3);
        r[REAL_mag_delay_used] = est->mag_delay;
        return fmi2OK;
    }
    if (valid_sample(gyr, acc)) return fmi2OK;
    int finite = 1;
    for (int i = 0; i < 3; i++) finite = finite && isfinite(gyr[i]) && isfinite(acc[i]);
    fmi2_log(instance, fmi2Warning, "t=%g: %s; estimate held", t,
             finite ? "input beyond every IMU's range" : "non-finite input");
    return fmi2Warning;
}

/* n samples of Ts from first (s) in turn, the inputs held: the worst status, at fmi2Error the first that failed */
static fmi2Status samples(Fmi2Instance *instance, Model *model, double first, double n) {
    const double Ts = model->estimator.step.Ts;
    fmi2Status status = fmi2OK;
    for (double k = 0.0; k < n; k++) {
        fmi2Status taken = sample(instance, model, first + k * Ts);
        if (taken == fmi2Error) return fmi2Error;
        if (taken > status) status = taken;
    }
    return status;
}

static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h) {
    Model *model = instance->state;
    const double Ts = model->estimator.step.Ts;
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE];
    if (!isfinite(t + h)) {
        fmi2_log(instance, fmi2Error, "a step of %s s to %s s overflows the estimator's arithmetic; the estimate held",
                 float_repr(h, a), float_repr(t + h, b));
        return fmi2Error;
    }
    const double n = grid_samples(instance->start_time, Ts, t, h);
    if (n > GRID_MAX_SAMPLES) {
        fmi2_log(instance, fmi2Error, "a step of %s s reaches %.0f samples of Ts = %s s; one step runs %.0f at most: "
                 "the estimate held", float_repr(h, a), n, float_repr(Ts, b), GRID_MAX_SAMPLES);
        return fmi2Error;
    }
    const double first = grid_before(instance->start_time, Ts, t);
    if (n <= 1.0) return n == 1.0 ? samples(instance, model, first, 1.0) : fmi2OK;
    /* a sample of Ts on inputs in every IMU's range keeps the outputs finite; a run of several falls back on
     * the state before it where one fails, a single one needs no copy (and is not slowed by it) */
    const Model before = *model;
    fmi2Real reals[N_REALS];
    memcpy(reals, instance->reals, sizeof reals);
    const fmi2Boolean valid = instance->booleans[BOOLEAN_valid];
    fmi2Status status = samples(instance, model, first, n);
    if (status == fmi2Error) {
        *model = before;
        memcpy(instance->reals, reals, sizeof reals);
        instance->booleans[BOOLEAN_valid] = valid;
    }
    return status;
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, sizeof(Model), initialise, step, validate, NULL,
};
