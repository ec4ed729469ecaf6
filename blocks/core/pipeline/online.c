/* online.c: the causal pipeline one sample at a time (see online.h). */
#include "pipeline/online.h"

#include <math.h>
#include <string.h>

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
