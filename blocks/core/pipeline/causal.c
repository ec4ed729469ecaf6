/* causal.c: the causal pipeline (see causal.h). */
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

int split_params(int method, const AfGiven *given, int n, int offset, int mag, AfGiven *own, int *n_own,
                 AfGiven *offset_given, int *n_offset, AfGiven *heading_given, int *n_heading, char *message,
                 size_t size)
{
    const int stages[3] = {method, AF_STAGE_gyro_offset, AF_STAGE_heading};
    const int runs[3] = {1, offset, mag};
    AfGiven *split[3] = {own, offset_given, heading_given};
    int *counts[3] = {n_own, n_offset, n_heading};
    for (int k = 0; k < n; k++) {
        int taken = 0;
        for (int s = 0; s < 3; s++)
            taken |= runs[s] && stage_param_named(stages[s], given[k].name) != NULL;
        if (!taken) {
            char known[2048] = "", name[64];
            for (int s = 0; s < 3; s++)
                if (runs[s])
                    append_names(known, sizeof known, stages[s]);
            return refuse(message, size, "unknown parameter %s (%s)", str_repr(given[k].name, name, sizeof name),
                          known);
        }
    }
    for (int s = 0; s < 3; s++) { /* each stage's values in its order of parameters */
        const AfStage *stage = &AF_STAGES[stages[s]];
        *counts[s] = 0;
        for (int i = 0; runs[s] && i < stage->n_params; i++)
            for (int k = 0; k < n; k++)
                if (strcmp(given[k].name, stage->params[i].name) == 0) {
                    split[s][(*counts[s])++] = given[k];
                    break;
                }
    }
    return 0;
}

int causal_configure(AfPipeline *pipeline, const char *method, const AfGiven *params, int n, int gyro_offset,
                     int heading, double latency, const char *gyr_samples, const char *acc_samples, char *message,
                     size_t size)
{
    AfGiven own[AF_N_PARAMS], offset_given[AF_N_PARAMS], heading_given[AF_N_PARAMS];
    int n_own, n_offset, n_heading;
    int index = method_index(method, message, size);
    memset(pipeline, 0, sizeof *pipeline);
    if (index < 0 || split_params(index, params, n, gyro_offset, heading, own, &n_own, offset_given, &n_offset,
                                  heading_given, &n_heading, message, size))
        return -1;
    if (method_configure(&pipeline->method, index, own, n_own, message, size))
        return -1;
    pipeline->offset_runs = gyro_offset != 0;
    pipeline->heading_runs = heading != 0;
    if (pipeline->offset_runs && resolve_given(AF_STAGE_gyro_offset, offset_given, n_offset, pipeline->offset_params,
                                               message, size))
        return -1;
    if (pipeline->heading_runs && resolve_given(AF_STAGE_heading, heading_given, n_heading, pipeline->heading_params,
                                                message, size))
        return -1;
    if (check_samples(gyr_samples, acc_samples, message, size) || check_latency(latency, message, size))
        return -1;
    pipeline->latency = latency;
    pipeline->point_gyr = strcmp(gyr_samples, "point") == 0;
    pipeline->mean_acc = strcmp(acc_samples, "mean") == 0;
    return 0;
}

/* the refusal of a stage whose coefficients overflow at Ts (the method's is the registry's) */
static int overflow(int stage, double Ts, char *message, size_t size)
{
    return refuse(message, size, "%s at Ts = %g s: its coefficients overflow", AF_STAGES[stage].owner, Ts);
}

/* 0, or -1 with the refusal of a sample time Ts (s) that is not finite and positive */
static int check_sample_time(double Ts, char *message, size_t size)
{
    char text[FLOAT_REPR_SIZE];
    if (isfinite(Ts) && Ts > 0)
        return 0;
    return refuse(message, size, "sample time must be a finite positive number of seconds, got %s",
                  float_repr(Ts, text));
}

int causal_at(const AfPipeline *pipeline, double Ts, const AfZoh *zoh, AfStep *step, char *message, size_t size)
{
    if (check_sample_time(Ts, message, size))
        return -1;
    step->Ts = Ts;
    if (stepper_at(&step->stepper, &pipeline->method, Ts, zoh, message, size))
        return -1;
    if (pipeline->offset_runs) {
        if (gyro_offset_coefficients(pipeline->offset_params, Ts, &step->offset_coef))
            return overflow(AF_STAGE_gyro_offset, Ts, message, size);
    }
    if (pipeline->heading_runs) {
        if (heading_coefficients(pipeline->heading_params, Ts, &step->heading_coef))
            return overflow(AF_STAGE_heading, Ts, message, size);
    }
    return 0;
}

void causal_initial_state(AfState *state)
{
    memset(state, 0, sizeof *state);
    heading_initial_state(&state->heading);
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

/* stage 1 over rows [i, j): gyr and acc in the project's convention into the hand-over */
static void timing_rows(const AfPipeline *pipeline, const AfStep *step, AfState *state, size_t i, size_t j,
                        const double *gyr, const double *acc, const AfHandover *handover)
{
    memcpy(handover->gyr, gyr + 3 * i, 3 * (j - i) * sizeof(double));
    memcpy(handover->acc, acc + 3 * i, 3 * (j - i) * sizeof(double));
    for (size_t k = 0; (pipeline->point_gyr || pipeline->mean_acc) && k < j - i; k++)
        sample_timing(pipeline, step, state, handover->gyr + 3 * k, handover->acc + 3 * k);
}

/* stage 2 over rows [i, j): the offset estimated and removed from the hand-over's gyr, the lever arm's
 * accelerations from its acc */
static void offset_rows(const AfStep *step, AfState *state, size_t i, size_t j, int starts,
                        const AfHandover *handover, const AfRows *out)
{
    double offset[3], variance[3]; /* where those outputs are not wanted */
    for (size_t k = 0; k < j - i; k++) {
        double *g = handover->gyr + 3 * k, *a = handover->acc + 3 * k;
        double *b = out->offset != NULL ? out->offset + 3 * (i + k) : offset;
        if (starts && k == 0)
            gyro_offset_initial_state(&step->offset_coef, g, a, &state->offset);
        gyro_offset_step(&state->offset, &step->offset_coef, g, a, b,
                         out->offset_variance != NULL ? out->offset_variance + 3 * (i + k) : variance, a);
        for (int c = 0; c < 3; c++)
            g[c] -= b[c];
    }
}

/* stage 3 over rows [i, j), started at rest on row i where the stages start there */
static void method_rows(const AfStep *step, AfState *state, size_t i, size_t j, int starts,
                        const double initial_gravity[3], const AfHandover *handover, const AfRows *out)
{
    if (starts) {
        double start[3];
        if (initial_gravity != NULL)
            memcpy(start, initial_gravity, sizeof start);
        else
            start_gravity(handover->gyr, handover->acc, step->Ts, start);
        stepper_initial_state(&step->stepper, start, state->method);
        state->started = 1;
    }
    stepper_run_rows(&step->stepper, state->method, j - i, handover->gyr, handover->acc, out->gravity + 3 * i,
                     out->quat + 4 * i);
}

/* stage 4 over rows [i, j): the quaternions turned to the magnetometer's heading */
static void heading_rows(const AfStep *step, AfState *state, size_t i, size_t j, const double *mag,
                         const AfRows *out)
{
    static const double no_field[3] = {NAN, NAN, NAN};
    for (size_t k = i; k < j; k++) {
        const double *f = mag != NULL ? mag + 3 * k : no_field;
        int accepted;
        heading_step(&state->heading, &step->heading_coef, out->quat + 4 * k, f, out->quat + 4 * k, &accepted);
        if (out->mag_accepted != NULL)
            out->mag_accepted[k] = accepted != 0;
        if (out->mag_offset != NULL)
            memcpy(out->mag_offset + 3 * k, state->heading.hard_iron.offset, 3 * sizeof(double));
        if (out->mag_delay != NULL)
            out->mag_delay[k] = state->heading.mag_delay.delay;
    }
}

/* stage 5 over rows [i, j): the estimate carried forward over the latency with the hand-over's gyr */
static void latency_rows(const AfPipeline *pipeline, size_t i, size_t j, const AfHandover *handover,
                         const AfRows *out)
{
    for (size_t k = 0; k < j - i; k++) {
        double *e = out->gravity + 3 * (i + k), *q = out->quat + 4 * (i + k);
        const double *g = handover->gyr + 3 * k;
        Quat carried;
        Vec3 up;
        carry_forward(quat_load(q), (Vec3){e[0], e[1], e[2]}, (Vec3){g[0], g[1], g[2]}, pipeline->latency, &carried,
                      &up);
        quat_store(carried, q);
        e[0] = up.x, e[1] = up.y, e[2] = up.z;
    }
}

int causal_stage_runs(const AfPipeline *pipeline, int stage)
{
    switch (stage) {
    case CAUSAL_OFFSET:
        return pipeline->offset_runs;
    case CAUSAL_HEADING:
        return pipeline->heading_runs;
    case CAUSAL_LATENCY:
        return pipeline->latency != 0.0;
    default:
        return 1;
    }
}

void causal_copy_stages(AfState *to, const AfState *from, int first, int last)
{
    for (int stage = first; stage < last; stage++) {
        switch (stage) {
        case CAUSAL_TIMING:
            to->has_last_gyr = from->has_last_gyr;
            memcpy(to->last_gyr, from->last_gyr, sizeof to->last_gyr);
            break;
        case CAUSAL_OFFSET:
            to->offset = from->offset;
            break;
        case CAUSAL_METHOD:
            to->started = from->started;
            memcpy(to->method, from->method, sizeof to->method);
            break;
        case CAUSAL_HEADING:
            to->heading = from->heading;
            break;
        default: /* the latency stage carries nothing */
            break;
        }
    }
}

void causal_run_stages(const AfPipeline *pipeline, const AfStep *step, AfState *state, int first, int last,
                       size_t i, size_t j, int starts, const AfInputs *in, const AfHandover *handover,
                       const AfRows *out)
{
    for (int stage = first; stage < last; stage++) {
        if (!causal_stage_runs(pipeline, stage))
            continue;
        switch (stage) {
        case CAUSAL_TIMING:
            timing_rows(pipeline, step, state, i, j, in->gyr, in->acc, handover);
            break;
        case CAUSAL_OFFSET:
            offset_rows(step, state, i, j, starts, handover, out);
            break;
        case CAUSAL_METHOD:
            method_rows(step, state, i, j, starts, in->initial_gravity, handover, out);
            break;
        case CAUSAL_HEADING:
            heading_rows(step, state, i, j, in->mag, out);
            break;
        default:
            latency_rows(pipeline, i, j, handover, out);
        }
    }
}

void causal_run_rows(const AfPipeline *pipeline, const AfStep *step, AfState *state, size_t n, const double *gyr,
                     const double *acc, const double *mag, const double initial_gravity[3], const AfRows *out)
{
    const AfInputs in = {gyr, acc, mag, initial_gravity};
    double g[CAUSAL_CHUNK][3], a[CAUSAL_CHUNK][3];
    const AfHandover handover = {g[0], a[0]};
    int starts = !state->started;
    for (size_t i = 0; i < n; i += CAUSAL_CHUNK) {
        size_t j = n - i < CAUSAL_CHUNK ? n : i + CAUSAL_CHUNK;
        causal_run_stages(pipeline, step, state, CAUSAL_TIMING, CAUSAL_STAGES, i, j, starts && i == 0, &in,
                          &handover, out);
    }
}

void causal_run(const AfPipeline *pipeline, const AfStep *step, AfState *state, const double gyr[3],
                const double acc[3], const double mag[3], AfRow *out)
{
    unsigned char accepted = 0;
    AfRows rows = {out->gravity, out->quat, out->offset, out->offset_variance, &accepted, out->mag_offset,
                   &out->mag_delay};
    causal_run_rows(pipeline, step, state, 1, gyr, acc, mag, NULL, &rows);
    out->mag_accepted = accepted;
}
