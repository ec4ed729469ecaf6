/* causal.c: Python twin blocks/pipeline/causal.py (valid_sample, split_params, configure, at,
 * State, run for one row), with the same refusals and messages. */
#include "pipeline/causal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "filters/sensor_frame.h"
#include "messages.h"
#include "params.h"
#include "stages/timing.h"

int valid_sample(const double gyr[3], const double acc[3])
{
    for (int i = 0; i < 3; i++)
        if (!(isfinite(gyr[i]) && fabs(gyr[i]) <= MAX_GYR_RAD_S && isfinite(acc[i]) && fabs(acc[i]) <= MAX_ACC_M_S2))
            return 0;
    return 1;
}

/* part appended to text (size bytes), cut where it does not fit */
static void append(char *text, size_t size, const char *part)
{
    size_t used = strlen(text);
    if (used + 1 < size)
        snprintf(text + used, size - used, "%s", part);
}

/* "<label>: name, name, ..." of a stage (its names, or "none") appended to text, after a "; " but for the first */
static void append_names(char *text, size_t size, int stage)
{
    const AfStage *s = &AF_STAGES[stage];
    if (text[0] != '\0')
        append(text, size, "; ");
    append(text, size, s->label);
    append(text, size, ": ");
    for (int i = 0; i < s->n_params; i++) {
        if (i > 0)
            append(text, size, ", ");
        append(text, size, s->params[i].name);
    }
    if (s->n_params == 0)
        append(text, size, "none");
}

int split_params(int method, const double given[AF_N_PARAMS], int offset, int mag, double own[AF_N_PARAMS],
                 double offset_given[AF_N_PARAMS], double heading_given[AF_N_PARAMS], char *message, size_t size)
{
    const int stages[3] = {method, AF_STAGE_gyro_offset, AF_STAGE_heading};
    const int runs[3] = {1, offset, mag};
    double *split[3] = {own, offset_given, heading_given};
    for (int i = 0; i < AF_N_PARAMS; i++) { /* in the order of the FMU's variables, as it gives them */
        int taken = 0;
        for (int s = 0; s < 3; s++) {
            int has = runs[s] && stage_param(stages[s], i) != NULL;
            split[s][i] = has ? given[i] : NAN;
            taken |= has;
        }
        if (!taken && !isnan(given[i])) {
            char known[2048] = "", name[64];
            for (int s = 0; s < 3; s++)
                if (runs[s])
                    append_names(known, sizeof known, stages[s]);
            return refuse(message, size, "unknown parameter %s (%s)", str_repr(AF_PARAMS[i].name, name, sizeof name),
                          known);
        }
    }
    return 0;
}

int causal_configure(AfPipeline *pipeline, const char *method, const double params[AF_N_PARAMS], int gyro_offset,
                     int heading, double latency, const char *gyr_samples, const char *acc_samples, char *message,
                     size_t size)
{
    double own[AF_N_PARAMS], offset_given[AF_N_PARAMS], heading_given[AF_N_PARAMS];
    int index = method_index(method, message, size);
    memset(pipeline, 0, sizeof *pipeline);
    if (index < 0 || split_params(index, params, gyro_offset, heading, own, offset_given, heading_given, message, size))
        return -1;
    if (method_configure(&pipeline->method, index, own, message, size))
        return -1;
    pipeline->offset_runs = gyro_offset != 0;
    pipeline->heading_runs = heading != 0;
    if (pipeline->offset_runs && resolve_params(AF_STAGE_gyro_offset, offset_given, pipeline->offset_params, message,
                                                size))
        return -1;
    if (pipeline->heading_runs && resolve_params(AF_STAGE_heading, heading_given, pipeline->heading_params, message,
                                                 size))
        return -1;
    if (check_samples(gyr_samples, acc_samples, message, size) || check_latency(latency, message, size))
        return -1;
    pipeline->latency = latency;
    pipeline->point_gyr = strcmp(gyr_samples, "point") == 0;
    pipeline->mean_acc = strcmp(acc_samples, "mean") == 0;
    return 0;
}

/* whether the n coefficients are finite; a NaN at index unset stands for a value not given */
static int finite_coefficients(const double *coef, int n, int unset)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(coef[i]) && !(i == unset && isnan(coef[i])))
            return 0;
    return 1;
}

/* the refusal of a stage whose coefficients overflow at Ts (the method's is the registry's) */
static int overflow(int stage, double Ts, char *message, size_t size)
{
    return refuse(message, size, "%s at Ts = %g s: its coefficients overflow", AF_STAGES[stage].owner, Ts);
}

int causal_at(const AfPipeline *pipeline, double Ts, AfStep *step, char *message, size_t size)
{
    char text[FLOAT_REPR_SIZE];
    if (!(isfinite(Ts) && Ts > 0))
        return refuse(message, size, "sample time must be a finite positive number of seconds, got %s",
                      float_repr(Ts, text));
    step->Ts = Ts;
    if (stepper_at(&step->stepper, &pipeline->method, Ts, message, size))
        return -1;
    if (pipeline->offset_runs) {
        gyro_offset_coefficients(pipeline->offset_params, Ts, step->offset_coef);
        if (!finite_coefficients(step->offset_coef, GYRO_OFFSET_COEF_SIZE, -1))
            return overflow(AF_STAGE_gyro_offset, Ts, message, size);
    }
    if (pipeline->heading_runs) {
        heading_coefficients(pipeline->heading_params, Ts, step->heading_coef);
        if (!finite_coefficients(step->heading_coef, HEADING_COEF_SIZE, 9)) /* coef[9]: mag_delay, NaN when unset */
            return overflow(AF_STAGE_heading, Ts, message, size);
    }
    return 0;
}

void causal_initial_state(AfState *state)
{
    memset(state, 0, sizeof *state);
    heading_initial_state(state->heading);
}

/* sample_timing: stage 1, gyr and acc in the project's convention; state->last_gyr carries a point sample over */
static void sample_timing(const AfPipeline *pipeline, const AfStep *step, AfState *state, double gyr[3], double acc[3])
{
    if (pipeline->point_gyr) {
        Vec3 raw = {gyr[0], gyr[1], gyr[2]};
        if (state->has_last_gyr) {
            Vec3 mean = interval_mean((Vec3){state->last_gyr[0], state->last_gyr[1], state->last_gyr[2]}, raw);
            gyr[0] = mean.x, gyr[1] = mean.y, gyr[2] = mean.z;
        }
        state->last_gyr[0] = raw.x, state->last_gyr[1] = raw.y, state->last_gyr[2] = raw.z;
        state->has_last_gyr = 1;
    }
    if (pipeline->mean_acc) {
        Vec3 end = interval_end((Vec3){gyr[0], gyr[1], gyr[2]}, (Vec3){acc[0], acc[1], acc[2]}, step->Ts);
        acc[0] = end.x, acc[1] = end.y, acc[2] = end.z;
    }
}

void causal_run(const AfPipeline *pipeline, const AfStep *step, AfState *state, const double gyr_in[3],
                const double acc_in[3], const double mag[3], AfRow *out)
{
    double gyr[3] = {gyr_in[0], gyr_in[1], gyr_in[2]}, acc[3] = {acc_in[0], acc_in[1], acc_in[2]};
    sample_timing(pipeline, step, state, gyr, acc);
    int starting = !state->started;
    if (pipeline->offset_runs) {
        if (starting)
            gyro_offset_initial_state(step->offset_coef, gyr, acc, state->offset);
        gyro_offset_step(state->offset, step->offset_coef, gyr, acc, out->offset, out->offset_variance);
        for (int i = 0; i < 3; i++)
            gyr[i] = gyr[i] - out->offset[i];
    }
    if (starting) {
        double gravity[3];
        start_gravity(gyr, acc, step->Ts, gravity);
        stepper_initial_state(&step->stepper, gravity, state->method);
        state->started = 1;
    }
    stepper_run(&step->stepper, state->method, gyr, acc, out->gravity, out->quat);
    if (pipeline->heading_runs) {
        Quat turned = heading_step(state->heading, step->heading_coef, quat_load(out->quat),
                                   (Vec3){mag[0], mag[1], mag[2]}, &out->mag_accepted);
        quat_store(turned, out->quat);
        for (int i = 0; i < 3; i++)
            out->mag_offset[i] = state->heading[HARD_IRON_OFFSET + i];
        out->mag_delay = state->heading[MAG_DELAY_IN_USE];
    }
    if (pipeline->latency != 0.0) {
        const double *g = out->gravity;
        Quat carried;
        Vec3 up;
        carry_forward(quat_load(out->quat), (Vec3){g[0], g[1], g[2]}, (Vec3){gyr[0], gyr[1], gyr[2]},
                      pipeline->latency, &carried, &up);
        quat_store(carried, out->quat);
        out->gravity[0] = up.x, out->gravity[1] = up.y, out->gravity[2] = up.z;
    }
}
