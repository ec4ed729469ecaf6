/* online.c: the causal pipeline one sample at a time (see online.h). */
#include "pipeline/online.h"

#include <math.h>
#include <string.h>

#include "messages.h"
#include "quaternion.h"
#include "stages/timing.h"

int af_online_init(AfOnline *est, const AfConfig *config, char *message, size_t size)
{
    AfPipeline pipeline;
    AfGiven given[AF_N_PARAMS];
    memset(est, 0, sizeof *est);
    if (causal_configure(&pipeline, config->method, given, given_values(config->params, given), config->gyro_offset,
                         config->heading, config->latency, config->gyr_samples ? config->gyr_samples : "mean",
                         config->acc_samples ? config->acc_samples : "point", message, size))
        return -1;
    af_online_of(est, &pipeline);
    return 0;
}

void af_online_of(AfOnline *est, const AfPipeline *pipeline)
{
    memset(est, 0, sizeof *est);
    est->pipeline = *pipeline;
    af_online_reset(est);
}

void af_online_reset(AfOnline *est)
{
    causal_initial_state(&est->state);
    memset(est->quat, 0, sizeof est->quat);
    memset(est->up, 0, sizeof est->up);
    memset(est->euler, 0, sizeof est->euler);
    memset(est->offset, 0, sizeof est->offset);
    est->quat[0] = 1.0;
    est->up[2] = 1.0;
    for (int i = 0; i < 3; i++)
        est->mag_offset[i] = est->state.heading.hard_iron.offset[i];
    est->mag_delay = est->state.heading.mag_delay.delay;
}

int af_online_discretise(AfOnline *est, double Ts, const AfZoh *zoh, char *message, size_t size)
{
    AfStep step;
    if (causal_at(&est->pipeline, Ts, zoh, &step, message, size))
        return -1;
    est->step = step;
    est->discretised = 1;
    return 0;
}

int af_online_step(AfOnline *est, const double gyr[3], const double acc[3], const double mag[3], double Ts,
                   char *message, size_t size)
{
    return af_online_step_with(est, gyr, acc, mag, Ts, NULL, message, size);
}

int af_online_step_with(AfOnline *est, const double gyr[3], const double acc[3], const double mag[3], double Ts,
                        const AfZoh *zoh, char *message, size_t size)
{
    if (!(est->discretised && same_step(Ts, est->step.Ts)) && af_online_discretise(est, Ts, zoh, message, size))
        return -1;
    int any_acc = acc[0] != 0.0 || acc[1] != 0.0 || acc[2] != 0.0;
    if (!(valid_sample(gyr, acc) && (est->state.started || any_acc))) {
        if (est->pipeline.point_gyr && isfinite(gyr[0]) && isfinite(gyr[1]) && isfinite(gyr[2])) {
            memcpy(est->state.last_gyr, gyr, sizeof est->state.last_gyr);
            est->state.has_last_gyr = 1;
        }
        return 0;
    }
    AfRow row;
    causal_run(&est->pipeline, &est->step, &est->state, gyr, acc, mag, &row);
    const double *g = row.gravity;
    double norm = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    memcpy(est->quat, row.quat, sizeof est->quat);
    for (int i = 0; i < 3; i++) {
        est->up[i] = g[i] / norm;
        est->offset[i] = est->pipeline.offset_runs ? row.offset[i] : 0.0;
        est->mag_offset[i] = est->state.heading.hard_iron.offset[i];
    }
    est->mag_delay = est->state.heading.mag_delay.delay;
    Vec3 euler = quat_euler_zyx(quat_load(est->quat));
    est->euler[0] = euler.x, est->euler[1] = euler.y, est->euler[2] = euler.z;
    return 1;
}

/* whether n doubles are all finite */
static int all_finite(const double *values, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(values[i])) return 0;
    return 1;
}

/* whether two discrete filters are the same: order, the entries of that order, D and Ts, bit for bit */
static int same_filter(const DiscreteFilter *a, const DiscreteFilter *b)
{
    if (a->n != b->n || a->n < 0 || a->n > MAX_ORDER) return 0;
    size_t n = (size_t)a->n;
    return memcmp(a->Ad, b->Ad, n * n * sizeof(double)) == 0 && memcmp(a->Bd, b->Bd, n * sizeof(double)) == 0 &&
           memcmp(a->C, b->C, n * sizeof(double)) == 0 && memcmp(&a->D, &b->D, sizeof a->D) == 0 &&
           memcmp(&a->Ts, &b->Ts, sizeof a->Ts) == 0;
}

/* whether two pipelines are the same, field by field, bit for bit (an earth filter's entries up to its order) */
static int same_pipeline(const AfPipeline *a, const AfPipeline *b)
{
    const AfMethod *x = &a->method, *y = &b->method;
    const EarthFilter *f = &x->filter, *g = &y->filter;
    if (x->method != y->method || x->kernel != y->kernel || memcmp(x->params, y->params, sizeof x->params) != 0 ||
        f->n != g->n || f->n < 0 || f->n > MAX_ORDER)
        return 0;
    size_t n = (size_t)f->n;
    return memcmp(f->A, g->A, n * n * sizeof(double)) == 0 && memcmp(f->B, g->B, n * sizeof(double)) == 0 &&
           memcmp(f->C, g->C, n * sizeof(double)) == 0 && memcmp(&f->D, &g->D, sizeof f->D) == 0 &&
           a->offset_runs == b->offset_runs && a->heading_runs == b->heading_runs &&
           memcmp(a->offset_params, b->offset_params, sizeof a->offset_params) == 0 &&
           memcmp(a->heading_params, b->heading_params, sizeof a->heading_params) == 0 &&
           memcmp(&a->latency, &b->latency, sizeof a->latency) == 0 && a->point_gyr == b->point_gyr &&
           a->mean_acc == b->mean_acc;
}

/* whether two steppers are the same: kernel, Ts, state size and the kernel's coefficients, bit for bit (what
 * is read of them: padding and a filter's entries beyond its order aside) */
static int same_stepper(const AfStepper *a, const AfStepper *b)
{
    if (a->kernel != b->kernel || a->state_size != b->state_size || memcmp(&a->Ts, &b->Ts, sizeof a->Ts) != 0)
        return 0;
    switch (a->kernel) {
    case KERNEL_NONE: return same_filter(&a->coef.sensor_frame, &b->coef.sensor_frame);
    case KERNEL_TSENG_ADAPTIVE: {
        const TsengAdaptiveCoef *x = &a->coef.tseng_adaptive, *y = &b->coef.tseng_adaptive;
        return same_filter(&x->disc, &y->disc) &&
               memcmp(&x->tol, &y->tol, sizeof *x - offsetof(TsengAdaptiveCoef, tol)) == 0;
    }
    case KERNEL_WIENER_LOCAL:
        return memcmp(&a->coef.wiener_local, &b->coef.wiener_local, sizeof a->coef.wiener_local) == 0;
    case KERNEL_LUINGE: return memcmp(&a->coef.luinge, &b->coef.luinge, sizeof a->coef.luinge) == 0;
    case KERNEL_MAHONY: return memcmp(&a->coef.mahony, &b->coef.mahony, sizeof a->coef.mahony) == 0;
    default: return 0;
    }
}

int af_online_validate(const AfOnline *est, const AfOnline *configured, char *message, size_t size)
{
    const AfPipeline *pipeline = &configured->pipeline;
    const AfState *state = &est->state;
    char text[FLOAT_REPR_SIZE];
    if (!same_pipeline(&est->pipeline, pipeline))
        return refuse(message, size, "the estimator's configuration is not that of its parameters");
    if (est->discretised != 0 && est->discretised != 1)
        return refuse(message, size, "the estimator's flag 'discretised' is %d, not 0 or 1", est->discretised);
    if (est->discretised) {
        AfStep step;
        memset(&step, 0, sizeof step);
        if (causal_at(pipeline, est->step.Ts, NULL, &step, message, size))
            return -1;
        if (!same_stepper(&est->step.stepper, &step.stepper) ||
            (pipeline->offset_runs && memcmp(&est->step.offset_coef, &step.offset_coef, sizeof step.offset_coef)) ||
            (pipeline->heading_runs && memcmp(&est->step.heading_coef, &step.heading_coef, sizeof step.heading_coef)))
            return refuse(message, size, "the estimator's discretisation is not its configuration's at Ts = %s s",
                          float_repr(est->step.Ts, text));
    }
    if ((state->has_last_gyr != 0 && state->has_last_gyr != 1) || (state->started != 0 && state->started != 1))
        return refuse(message, size, "the estimator's flags 'has_last_gyr' and 'started' must be 0 or 1");
    if (state->started && !est->discretised)
        return refuse(message, size, "the estimator started without a discretisation");
    if (!all_finite(state->last_gyr, 3) || !af_finite(&state->offset, sizeof state->offset, NULL) ||
        !af_finite(&state->heading, sizeof state->heading, NULL))
        return refuse(message, size, "the estimator's stages hold values that are not finite");
    if (!all_finite(state->method, AF_STEPPER_STATE_MAX) ||
        (state->started && !stepper_state_valid(&est->step.stepper, state->method)))
        return refuse(message, size, "the estimator's method holds values that are not finite or no unit quaternion");
    if (!all_finite(est->quat, 4) || !all_finite(est->up, 3) || !all_finite(est->euler, 3) ||
        !all_finite(est->offset, 3) || !all_finite(est->mag_offset, 3) || !isfinite(est->mag_delay))
        return refuse(message, size, "the estimator's outputs are not finite");
    return 0;
}
