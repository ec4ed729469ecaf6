/* kinds.c: the C step of each kind of diagram block (see kinds.h). */
#include "diagram/kinds.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "delay_line.h"
#include "earth_field.h"
#include "errors.h"
#include "messages.h"
#include "profile_params.h"
#include "stages/fields.h"
#include "stages/timing.h"

#define MAX_SAMPLES 9007199254740992.0 /* 2^53: the sample counts a double holds exactly */

static const char *const KIND_NAMES[DIAGRAM_KINDS] = {
    [DIAGRAM_LTI] = "lti", [DIAGRAM_METHOD] = "method", [DIAGRAM_FILTER] = "filter",
    [DIAGRAM_GYRO_OFFSET] = "gyro_offset", [DIAGRAM_HEADING] = "heading", [DIAGRAM_LATENCY] = "latency",
    [DIAGRAM_IMU] = "imu", [DIAGRAM_MAGNETOMETER] = "magnetometer", [DIAGRAM_HUMAN] = "human",
    [DIAGRAM_CLOSED_FORM] = "closed_form", [DIAGRAM_ERROR] = "error",
};

/* The inputs and outputs of each kind but LTI (whose are its matrices'). */
static const size_t KIND_INPUTS[DIAGRAM_KINDS] = {
    [DIAGRAM_METHOD] = 6, [DIAGRAM_FILTER] = 6, [DIAGRAM_GYRO_OFFSET] = 6, [DIAGRAM_HEADING] = 7,
    [DIAGRAM_LATENCY] = 10, [DIAGRAM_IMU] = 12, [DIAGRAM_MAGNETOMETER] = 7, [DIAGRAM_HUMAN] = 6,
    [DIAGRAM_CLOSED_FORM] = 0, [DIAGRAM_ERROR] = 7,
};
static const size_t KIND_OUTPUTS[DIAGRAM_KINDS] = {
    [DIAGRAM_METHOD] = 7, [DIAGRAM_FILTER] = 7, [DIAGRAM_GYRO_OFFSET] = 9, [DIAGRAM_HEADING] = 7,
    [DIAGRAM_LATENCY] = 7, [DIAGRAM_IMU] = 6, [DIAGRAM_MAGNETOMETER] = 3, [DIAGRAM_HUMAN] = HUMAN_N_OUT,
    [DIAGRAM_CLOSED_FORM] = 10, [DIAGRAM_ERROR] = 1,
};

/* A block's state array as the core's state struct (an array of doubles, as the struct's members) */
#define STATE(type, state) ((type *)(void *)(state))
#define DOUBLES(type) (sizeof(type) / sizeof(double))

const char *kind_name(DiagramKind kind)
{
    return (int)kind >= 0 && kind < DIAGRAM_KINDS ? KIND_NAMES[kind] : "unknown";
}

static int all_zero(const double *values, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (values[i] != 0.0) return 0;
    return 1;
}

/* 0, or -1 with the message unless the block has the kind's inputs, outputs and states */
static int check_counts(const DiagramBlock *b, size_t states, char *message, size_t size)
{
    size_t inputs = KIND_INPUTS[b->kind], outputs = KIND_OUTPUTS[b->kind];
    if (b->n_inputs == inputs && b->n_outputs == outputs && b->n_states == states) return 0;
    return refuse(message, size, "a %s block has %lu inputs, %lu outputs and %lu states, the diagram gives it %lu, %lu "
                  "and %lu", KIND_NAMES[b->kind], (unsigned long)inputs, (unsigned long)outputs, (unsigned long)states,
                  (unsigned long)b->n_inputs, (unsigned long)b->n_outputs, (unsigned long)b->n_states);
}

/* 0, or -1 with the message unless the block has n numbers (numbers not NULL where n > 0), finite where
 * finite is 1 */
static int check_numbers(const DiagramBlock *b, size_t n, int finite, char *message, size_t size)
{
    if (b->n_numbers != n || (n > 0 && b->numbers == NULL))
        return refuse(message, size, "a %s block takes %lu numbers, the diagram gives it %lu", KIND_NAMES[b->kind],
                      (unsigned long)n, (unsigned long)(b->numbers == NULL ? 0 : b->n_numbers));
    if (finite && !af_finite(b->numbers, n * sizeof(double), NULL))
        return refuse(message, size, "its numbers must be finite");
    return 0;
}

/* The given parameters (names[i] = numbers[i]) into given (AF_N_PARAMS), their count into *n; those whose
 * value is NaN left out where skip_nan (a Python None: not given, as the stages' bindings take them).
 * 0, or -1 with the message. */
static int given_params(const DiagramBlock *b, int skip_nan, AfGiven given[AF_N_PARAMS], int *n, char *message,
                        size_t size)
{
    *n = 0;
    if (b->n_numbers > AF_N_PARAMS)
        return refuse(message, size, "%lu parameters given, there are %d", (unsigned long)b->n_numbers, AF_N_PARAMS);
    if (b->n_numbers > 0 && (b->numbers == NULL || b->names == NULL))
        return refuse(message, size, "its %lu parameters have no names or no values", (unsigned long)b->n_numbers);
    for (size_t i = 0; i < b->n_numbers; i++) {
        if (b->names[i] == NULL) return refuse(message, size, "its parameter %lu has no name", (unsigned long)i);
        if (!(skip_nan && isnan(b->numbers[i]))) given[(*n)++] = (AfGiven){b->names[i], b->numbers[i], NULL};
    }
    return 0;
}

/* the entry k of the LTI block's matrices A, B, C, D (laid out from the Real at its parameter) as "C[1,0]", the
 * name of its FMI 2.0 variable */
static const char *lti_entry(const LtiCoef *c, size_t k, char *out, size_t size)
{
    const size_t offsets[4] = {0, c->n * c->n, c->n * c->n + c->n * c->m, c->n * c->n + c->n * c->m + c->p * c->n};
    const size_t columns[4] = {c->n, c->m, c->n, c->m};
    int matrix = 3;
    while (k < offsets[matrix]) matrix--;
    k -= offsets[matrix];
    snprintf(out, size, "%c[%lu,%lu]", "ABCD"[matrix], (unsigned long)(k / columns[matrix]),
             (unsigned long)(k % columns[matrix]));
    return out;
}

static int configure_lti(const DiagramBlock *b, const double *reals, size_t n_reals, LtiCoef *c, char *message,
                         size_t size)
{
    char at[64], value[FLOAT_REPR_SIZE];
    c->n = b->n_states, c->m = b->n_inputs, c->p = b->n_outputs;
    c->continuous = b->dt == 0.0;
    if (!(isfinite(b->dt) && b->dt >= 0.0))
        return refuse(message, size, "its sample time must be a finite number of seconds, 0 or more, got %s",
                      float_repr(b->dt, value));
    if (c->n > DIAGRAM_LTI_MAX || c->m > DIAGRAM_LTI_MAX - c->n)
        return refuse(message, size, "it has %lu states and %lu inputs, an FMU takes at most %d together",
                      (unsigned long)c->n, (unsigned long)c->m, DIAGRAM_LTI_MAX);
    if (c->p > n_reals || b->parameter > n_reals)
        return refuse(message, size, "its matrices are beyond the FMU's %lu Reals", (unsigned long)n_reals);
    size_t count = c->n * c->n + c->n * c->m + c->p * c->n + c->p * c->m, d = count - c->p * c->m;
    if (count > n_reals - b->parameter)
        return refuse(message, size, "its matrices (%lu numbers from Real %lu) are beyond the FMU's %lu Reals",
                      (unsigned long)count, (unsigned long)b->parameter, (unsigned long)n_reals);
    const double *x = reals + b->parameter;
    for (size_t k = 0; k < count; k++) {
        if (!isfinite(x[k]))
            return refuse(message, size, "its matrices must be finite, %s = %s", lti_entry(c, k, at, sizeof at),
                          float_repr(x[k], value));
        if (k >= d && !b->feedthrough && x[k] != 0.0)
            return refuse(message, size, "exported with D = 0 (no feedthrough), it has %s = %s; export the diagram "
                          "again with this D", lti_entry(c, k, at, sizeof at), float_repr(x[k], value));
    }
    return 0;
}

/* FILTER: [n, Ad (n x n), Bd (n), C (n), D] at the block's dt */
static int configure_filter(const DiagramBlock *b, AfStepper *s, char *message, size_t size)
{
    DiscreteFilter d;
    memset(&d, 0, sizeof d);
    if (b->n_numbers < 1 || b->numbers == NULL || !(b->numbers[0] >= 0.0 && b->numbers[0] <= MAX_ORDER) ||
        b->numbers[0] != floor(b->numbers[0]))
        return refuse(message, size, "a filter block's numbers begin with its order, a whole number 0 ... %d",
                      MAX_ORDER);
    d.n = (int)b->numbers[0];
    size_t n = (size_t)d.n;
    if (check_numbers(b, 1 + n * n + 2 * n + 1, 1, message, size)) return -1;
    memcpy(d.Ad, b->numbers + 1, n * n * sizeof(double));
    memcpy(d.Bd, b->numbers + 1 + n * n, n * sizeof(double));
    memcpy(d.C, b->numbers + 1 + n * n + n, n * sizeof(double));
    d.D = b->numbers[1 + n * n + 2 * n];
    d.Ts = b->dt;
    return stepper_of_filter(s, &d, message, size);
}

static int configure_method(const DiagramBlock *b, AfStepper *s, char *message, size_t size)
{
    AfGiven given[AF_N_PARAMS];
    AfMethod method;
    int n, index = method_index(b->text, message, size);
    if (index < 0 || given_params(b, 0, given, &n, message, size) ||
        method_configure(&method, index, given, n, message, size))
        return -1;
    return stepper_at(s, &method, b->dt, NULL, message, size);
}

/* GYRO_OFFSET, HEADING: the stage's given parameters resolved, its coefficients at the block's dt */
static int configure_stage(const DiagramBlock *b, int stage, KindCoef *c, char *message, size_t size)
{
    AfGiven given[AF_N_PARAMS];
    double resolved[AF_N_PARAMS];
    int n;
    if (given_params(b, 1, given, &n, message, size) || resolve_given(stage, given, n, resolved, message, size))
        return -1;
    int status = stage == AF_STAGE_gyro_offset ? gyro_offset_coefficients(resolved, b->dt, &c->gyro_offset)
                                               : heading_coefficients(resolved, b->dt, &c->heading);
    return status ? refuse(message, size, "%s at Ts = %g s: its coefficients overflow", AF_STAGES[stage].owner, b->dt)
                  : 0;
}

/* IMU, MAGNETOMETER: [ImuModel.vector (IMU_VECTOR_SIZE), fs]; the states an IMU's delay line takes into *states */
static int configure_imu(const DiagramBlock *b, ImuCoef *c, size_t *states, char *message, size_t size)
{
    char value[FLOAT_REPR_SIZE];
    if (check_numbers(b, IMU_VECTOR_SIZE + 1, 0, message, size)) return -1;
    if (imu_from_vector(b->numbers, &c->params, message, size)) return -1;
    c->fs = b->numbers[IMU_VECTOR_SIZE];
    if (!(isfinite(c->fs) && c->fs > 0.0))
        return refuse(message, size, "its sample rate must be a finite positive number of Hz, got %s",
                      float_repr(c->fs, value));
    *states = 0;
    if (b->kind == DIAGRAM_IMU && c->params.latency) {
        static const double zeros[DELAY_WIDTH] = {0.0};
        DelayLine line;
        if (delay_init(&line, c->params.latency, c->fs, zeros, message, size)) return -1;
        *states = (size_t)(line.rows - 1) * DELAY_WIDTH; /* ImuModel.delay_state's */
    }
    return 0;
}

/* CLOSED_FORM: text the profile's name; [its parameters..., g] */
static int configure_closed_form(const DiagramBlock *b, ClosedForm *c, char *message, size_t size)
{
    char name[64];
    int profile = b->text ? closed_form_profile(b->text) : -1;
    const SimProfile *table = b->text ? profile_named(b->text) : NULL;
    if (profile < 0 || table == NULL)
        return refuse(message, size, "%s is no closed-form profile",
                      b->text ? str_repr(b->text, name, sizeof name) : "None");
    if (b->n_numbers < 1 || b->numbers == NULL)
        return refuse(message, size, "a closed_form block's numbers end with g, it has none");
    size_t n = b->n_numbers - 1;
    if (profile_check(table, b->numbers, n, b->numbers[n], message, size)) return -1;
    c->profile = (ClosedFormProfile)profile;
    memcpy(c->p, b->numbers, n * sizeof(double)); /* n: the profile's count, at most CLOSED_FORM_MAX_PARAMS */
    c->g = b->numbers[n];
    return 0;
}

int kind_configure(const DiagramBlock *b, const double *reals, size_t n_reals, KindCoef *coef, char *message,
                   size_t size)
{
    char value[FLOAT_REPR_SIZE];
    size_t states = 0;
    memset(coef, 0, sizeof *coef);
    if (!((int)b->kind >= 0 && b->kind < DIAGRAM_KINDS))
        return refuse(message, size, "its kind %d is none of the %d kinds", (int)b->kind, DIAGRAM_KINDS);
    if ((b->feedthrough != 0 && b->feedthrough != 1) || (b->start != 0 && b->start != 1))
        return refuse(message, size, "its flags feedthrough (%d) and start (%d) must be 0 or 1", b->feedthrough,
                      b->start);
    if (b->kind == DIAGRAM_LTI) {
        if (b->start) return refuse(message, size, "an lti block does not start at rest (start 1)");
        return configure_lti(b, reals, n_reals, &coef->lti, message, size);
    }
    if (!b->feedthrough) return refuse(message, size, "a %s block has feedthrough (feedthrough 0)", KIND_NAMES[b->kind]);
    if (b->start && !(b->kind == DIAGRAM_METHOD || b->kind == DIAGRAM_FILTER || b->kind == DIAGRAM_GYRO_OFFSET ||
                      b->kind == DIAGRAM_HEADING))
        return refuse(message, size, "a %s block does not start at rest (start 1)", KIND_NAMES[b->kind]);
    if (!(isfinite(b->dt) && b->dt > 0.0))
        return refuse(message, size, "sample time must be a finite positive number of seconds, got %s",
                      float_repr(b->dt, value));
    int status = 0;
    switch (b->kind) {
    case DIAGRAM_METHOD:
    case DIAGRAM_FILTER:
        status = b->kind == DIAGRAM_METHOD ? configure_method(b, &coef->stepper, message, size)
                                           : configure_filter(b, &coef->stepper, message, size);
        states = (size_t)coef->stepper.state_size;
        break;
    case DIAGRAM_GYRO_OFFSET:
        status = configure_stage(b, AF_STAGE_gyro_offset, coef, message, size);
        states = DOUBLES(AfGyroOffset);
        break;
    case DIAGRAM_HEADING:
        status = configure_stage(b, AF_STAGE_heading, coef, message, size);
        states = DOUBLES(AfHeading);
        break;
    case DIAGRAM_LATENCY:
        status = check_numbers(b, 1, 0, message, size) || check_latency(b->numbers[0], message, size);
        if (!status) coef->latency = b->numbers[0];
        break;
    case DIAGRAM_IMU:
    case DIAGRAM_MAGNETOMETER: status = configure_imu(b, &coef->imu, &states, message, size); break;
    case DIAGRAM_HUMAN:
        status = check_numbers(b, HUMAN_N_COEF, 1, message, size);
        if (!status && !(b->numbers[4] > 0.0))
            status = refuse(message, size, "its time step Ts (its numbers' fifth) must be positive, got %s",
                            float_repr(b->numbers[4], value));
        if (!status) memcpy(coef->human, b->numbers, sizeof coef->human);
        states = HUMAN_N_STATES;
        break;
    case DIAGRAM_CLOSED_FORM:
        status = configure_closed_form(b, &coef->closed_form, message, size);
        states = 1;
        break;
    default: status = check_numbers(b, 0, 0, message, size); /* DIAGRAM_ERROR */
    }
    return status ? -1 : check_counts(b, states, message, size);
}

void lti_output(const LtiCoef *c, const LtiMatrices *lti, const double *x, const double *u, double *y)
{
    for (size_t i = 0; i < c->p; i++) {
        double s = 0.0;
        for (size_t j = 0; j < c->n; j++) s += lti->C[i * c->n + j] * x[j];
        for (size_t j = 0; u != NULL && j < c->m; j++) s += lti->D[i * c->m + j] * u[j];
        y[i] = s;
    }
}

void lti_update(const LtiCoef *c, const LtiMatrices *lti, const double *x, const double *u, double *next)
{
    for (size_t i = 0; i < c->n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < c->n; j++) s += lti->A[i * c->n + j] * x[j];
        for (size_t j = 0; j < c->m; j++) s += lti->B[i * c->m + j] * u[j];
        next[i] = s;
    }
}

/* the state the block starts from at rest on its first inputs u (the Python block's start) */
static void start(const DiagramBlock *b, const KindCoef *c, const double *u, double *state)
{
    double gravity[3];
    switch (b->kind) {
    case DIAGRAM_METHOD:
    case DIAGRAM_FILTER: /* stepper.initial_state(start_gravity(gyr, acc, dt)) */
        start_gravity(u, u + 3, b->dt, gravity);
        stepper_initial_state(&c->stepper, gravity, state);
        break;
    case DIAGRAM_GYRO_OFFSET: gyro_offset_initial_state(&c->gyro_offset, u, u + 3, STATE(AfGyroOffset, state)); break;
    default: heading_initial_state(STATE(AfHeading, state)); /* DIAGRAM_HEADING: kind_configure allows no other */
    }
}

void kind_step(const DiagramBlock *b, const KindCoef *c, const LtiMatrices *lti, const double *x, const double *u,
               double *y, double *next)
{
    double offset[3], variance[3], delay, field[3];
    unsigned char accepted;
    if (b->kind == DIAGRAM_LTI) {
        lti_output(&c->lti, lti, x, u, y);
        lti_update(&c->lti, lti, x, u, next);
        return;
    }
    if (b->n_states > 0) memcpy(next, x, b->n_states * sizeof(double));
    if (b->start && b->n_states > 0 && all_zero(next, b->n_states)) start(b, c, u, next);
    switch (b->kind) {
    case DIAGRAM_METHOD:
    case DIAGRAM_FILTER: stepper_run(&c->stepper, next, u, u + 3, y, y + 3); break;
    case DIAGRAM_GYRO_OFFSET: /* gyr - offset, offset, acc less the lever arm's accelerations */
        gyro_offset_step(STATE(AfGyroOffset, next), &c->gyro_offset, u, u + 3, offset, variance, y + 6);
        for (int i = 0; i < 3; i++) y[i] = u[i] - offset[i], y[3 + i] = offset[i];
        break;
    case DIAGRAM_HEADING: /* qh, mag_offset */
        heading_run(STATE(AfHeading, next), &c->heading, 1, u, u + 4, y, &accepted, y + 4, &delay);
        break;
    case DIAGRAM_LATENCY: /* u: gyr, q, ghat; y: q and ghat carried forward */
        memcpy(y, u + 3, 7 * sizeof(double));
        carry_forward_rows(1, y, y + 4, u, c->latency);
        break;
    case DIAGRAM_IMU: { /* u: omega, f, n, na */
        double late[DELAY_WIDTH];
        const double *measured = u;
        if (c->imu.params.latency) { /* the delay line of the state (ImuModel.delay_step) */
            static const double zeros[DELAY_WIDTH] = {0.0};
            DelayLine line;
            delay_init(&line, c->imu.params.latency, c->imu.fs, zeros, NULL, 0); /* kind_configure took it */
            delay_load(&line, next);
            delay_step(&line, u, late);
            delay_save(&line, next);
            measured = late;
        }
        imu_measure(&c->imu.params, measured, measured + 3, u + 6, c->imu.fs, y, y + 3);
        break;
    }
    case DIAGRAM_MAGNETOMETER: /* u: qt, nm */
        earth_field_in_sensor(u, field);
        imu_measure_mag(&c->imu.params, field, u + 4, c->imu.fs, y);
        break;
    case DIAGRAM_HUMAN: human_step(next, u, c->human, y); break;
    case DIAGRAM_CLOSED_FORM: /* state: the samples taken, k; sample k is the interval ending at (k + 1) dt */
        closed_form_at(&c->closed_form, (next[0] + 1.0) * b->dt, b->dt, y, y + 3, y + 6);
        next[0] += 1.0;
        break;
    default: y[0] = attitude_error(u, u + 3); /* DIAGRAM_ERROR: u ghat, qt */
    }
}

int kind_validate(const DiagramBlock *b, const KindCoef *c, const double *state, char *message, size_t size)
{
    char value[FLOAT_REPR_SIZE];
    if (!af_finite(state, b->n_states * sizeof(double), NULL)) return refuse(message, size, "its state holds values that are not finite");
    if ((b->kind == DIAGRAM_METHOD || b->kind == DIAGRAM_FILTER) && !all_zero(state, b->n_states) &&
        !stepper_state_valid(&c->stepper, state))
        return refuse(message, size, "its state's quaternion is not a unit one");
    if (b->kind == DIAGRAM_CLOSED_FORM && !(state[0] >= 0.0 && state[0] <= MAX_SAMPLES && state[0] == floor(state[0])))
        return refuse(message, size, "its state, the samples taken, is %s, not a whole number 0 ... 2**53",
                      float_repr(state[0], value));
    return 0;
}
