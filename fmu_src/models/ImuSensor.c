/* ImuSensor.c: the model of the native ImuSensor.fmu: its variables (ImuSensor_variables.h,
 * generated from systems/fmi/interface/simulation_variables.py) onto the simulation's sensor model (sensor.h),
 * delay line (delay_line.h) and noise streams (noise.h): step k draws sample k of the
 * streams SENSOR and MAGNETOMETER of `seed`, as ImuModel.apply and apply_mag draw them.
 * With a latency the first step's size is the sensor's sample time, and later steps run on its grid
 * from the start time (timing.h: grid_samples): the samples a step reaches, its inputs held; none (a master's
 * shortfall of picoseconds, half a sample) holds the outputs; several run in turn. Without one, each
 * step is a sample of its own length. Before the first step (in Initialization Mode and after it) the outputs
 * are the sensor's model of its inputs without noise, which a Jacobi master hands on before any step.
 * The pythonfmu ImuSensor (fmu_src/ImuSensor.py) runs the same C core with the same checks,
 * messages and statuses. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "ImuSensor_variables.h"
#include "messages.h"
#include "delay_line.h"
#include "noise.h"
#include "stages/timing.h"
#include "sensor.h"

#define MESSAGE_SIZE 512

typedef struct {
    ImuParams params;
    uint64_t seed, k; /* the noise streams' seed; the steps taken */
    double step_size; /* the first step's, s: a latency needs a fixed step */
    DelayLine delay;
} Model;

static void copy3(double to[3], const fmi2Real *from) {
    for (int i = 0; i < 3; i++) to[i] = from[i];
}

static fmi2Status initialise(Fmi2Instance *instance) {
    Model *model = instance->state;
    const fmi2Real *r = instance->reals;
    ImuParams *p = &model->params;
    char message[MESSAGE_SIZE];
    /* each vector's components are consecutive in the table: x, y, z; gyr_scale_<row>_<c> and
     * mag_soft_iron_<row>_<c> row by row */
    p->delta_n = r[REAL_delta_n];
    copy3(p->gyr_offset, &r[REAL_gyr_offset_x]);
    for (int i = 0; i < 9; i++) p->gyr_scale[i] = r[REAL_gyr_scale_x_x + i];
    p->acc_noise = r[REAL_acc_noise];
    copy3(p->acc_offset, &r[REAL_acc_offset_x]);
    p->latency = r[REAL_latency];
    p->mag_noise = r[REAL_mag_noise];
    copy3(p->mag_offset, &r[REAL_mag_offset_x]);
    for (int i = 0; i < 9; i++) p->mag_soft_iron[i] = r[REAL_mag_soft_iron_x_x + i];
    if (imu_check(p, message, sizeof message) != 0 ||
        check_seed(instance->integers[INTEGER_seed], &model->seed, message, sizeof message) != 0) {
        fmi2_log(instance, fmi2Error, "invalid parameter: %s", message);
        return fmi2Error;
    }
    model->k = 0;
    return fmi2OK;
}

static int validate(const void *state, const void *configured, char *message, size_t size) {
    const Model *model = state, *own = configured;
    if (memcmp(&model->params, &own->params, sizeof own->params) != 0 || model->seed != own->seed)
        return refuse(message, size, "the sensor's parameters or seed are not those of its configuration");
    if (!model->params.latency || model->k == 0) return 0; /* no delay line in use */
    if (!(isfinite(model->step_size) && model->step_size > 0.0 && isfinite(1.0 / model->step_size)))
        return refuse(message, size, "the sensor's step size is not a finite positive number of seconds");
    return delay_validate(&model->delay, model->params.latency, 1.0 / model->step_size, message, size);
}

/* one sample of h (s) of the inputs as they are: the outputs, the delay line stepped (a latency) */
static void sample(Fmi2Instance *instance, Model *model, double h) {
    fmi2Real *r = instance->reals;
    double signals[DELAY_WIDTH], late[DELAY_WIDTH], noise[SENSOR_WIDTH], mag_noise[MAGNETOMETER_WIDTH];
    for (int i = 0; i < 3; i++) signals[i] = r[REAL_omega_x + i], signals[3 + i] = r[REAL_f_x + i];
    const double *measured = signals;
    if (model->params.latency) {
        delay_step(&model->delay, signals, late);
        measured = late;
    }
    noise_normals(model->seed, SENSOR, model->k, SENSOR_WIDTH, noise);
    imu_measure(&model->params, measured, measured + 3, noise, 1.0 / h, &r[REAL_gyr_x], &r[REAL_acc_x]);
    noise_normals(model->seed, MAGNETOMETER, model->k, MAGNETOMETER_WIDTH, mag_noise);
    imu_measure_mag(&model->params, &r[REAL_m_x], mag_noise, 1.0 / h, &r[REAL_mag_x]);
    model->k++;
}

static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h) {
    Model *model = instance->state;
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE], message[MESSAGE_SIZE];
    if (!isfinite(1.0 / h) || !isfinite(t + h)) { /* a sample rate or an end beyond the arithmetic's range */
        fmi2_log(instance, fmi2Error, "a step of %s s to %s s overflows the sensor's arithmetic", float_repr(h, a),
                 float_repr(t + h, b));
        return fmi2Error;
    }
    if (!model->params.latency) {
        sample(instance, model, h);
        return fmi2OK;
    }
    if (model->k == 0) { /* the first step: the sample time, the delay line filled with the inputs */
        double signals[DELAY_WIDTH];
        for (int i = 0; i < 3; i++)
            signals[i] = instance->reals[REAL_omega_x + i], signals[3 + i] = instance->reals[REAL_f_x + i];
        if (delay_init(&model->delay, model->params.latency, 1.0 / h, signals, message, sizeof message) != 0) {
            fmi2_log(instance, fmi2Error, "%s", message);
            return fmi2Error;
        }
        model->step_size = h;
        sample(instance, model, h);
        return fmi2OK;
    }
    const double n = grid_samples(instance->start_time, model->step_size, t, h);
    if (n > GRID_MAX_SAMPLES) {
        fmi2_log(instance, fmi2Error, "a step of %s s reaches %.0f samples of the sensor's sample time %s s (its "
                 "first step's); one step runs %.0f at most", float_repr(h, a), n, float_repr(model->step_size, b),
                 GRID_MAX_SAMPLES);
        return fmi2Error;
    }
    for (double k = 0.0; k < n; k++) sample(instance, model, model->step_size);
    return fmi2OK;
}

/* before the first step: the sensor's model of its inputs as they are, with no noise (no sample is drawn
 * before a step; with a latency, the inputs are those the delay line starts filled with) */
static void start(Fmi2Instance *instance) {
    const Model *model = instance->state;
    fmi2Real *r = instance->reals;
    const double none[SENSOR_WIDTH > MAGNETOMETER_WIDTH ? SENSOR_WIDTH : MAGNETOMETER_WIDTH] = {0.0};
    imu_measure(&model->params, &r[REAL_omega_x], &r[REAL_f_x], none, 1.0, &r[REAL_gyr_x], &r[REAL_acc_x]);
    imu_measure_mag(&model->params, &r[REAL_m_x], none, 1.0, &r[REAL_mag_x]);
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, sizeof(Model), initialise, step, validate, start,
};
