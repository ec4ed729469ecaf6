/* online.h: the causal pipeline one sample at a time (an FMU's doStep), the sample time taken
 * from each call. Python twin: blocks/pipeline/online.py (OnlineEstimator). */
#ifndef AF_ONLINE_H
#define AF_ONLINE_H

#include <stddef.h>

#include "af_params.h"        /* AF_N_PARAMS and the index of every tuning parameter (generated) */
#include "pipeline/causal.h"

/* What OnlineEstimator's constructor takes. */
typedef struct {
    const char *method;         /* "wiener", "first_order", "luinge", "tseng", "tseng_adaptive", "mahony" */
    double params[AF_N_PARAMS]; /* every tuning parameter by its generated index; NaN: not given */
    int heading;                /* 1: the magnetometer's heading stage runs (FMU heading "mag") */
    int gyro_offset;            /* 1: the gyro-offset stage runs */
    double latency;             /* s, within +-MAX_LATENCY_S */
    const char *gyr_samples;    /* "mean" or "point" (blocks.stages.timing); NULL: "mean" */
    const char *acc_samples;    /* "point" or "mean"; NULL: "point" */
} AfConfig;

/* The whole estimator: configuration, the discretisation at the last Ts, every stage's state
 * and the outputs. Plain data, no pointers: an FMU state is a copy of it. */
typedef struct {
    AfPipeline pipeline;        /* the configuration, validated */
    AfStep step;                /* the pipeline at the last sample time; step.Ts == 0: none yet */
    AfState state;              /* what the stages carry from sample to sample */
    int ready;                  /* 1 once a sample was taken (the stages started) */
    /* the estimate after the last sample taken */
    double quat[4];             /* sensor -> earth, [w, x, y, z] */
    double up[3];               /* unit up-vector, sensor coordinates */
    double euler[3];            /* roll, pitch, yaw (rad, Z-Y-X) of quat */
    double offset[3];           /* gyro-offset estimate (rad/s; 0 without that stage) */
    double mag_offset[3];       /* hard-iron offset estimate (uT; 0 until one is proven) */
    double mag_delay;           /* the magnetometer's delay the heading allows for (s) */
} AfOnline;

/* 0, or -1 with a message (the refusals of blocks.pipeline.causal.configure, its messages). */
int af_online_init(AfOnline *est, const AfConfig *config, char *message, size_t size);

/* Forget every sample; the configuration stays (OnlineEstimator.reset). */
void af_online_reset(AfOnline *est);

/* The pipeline discretised at Ts (s) now, as the next step would: 0, or -1 with a message (Ts not
 * finite and positive, or parameters whose coefficients at Ts are not finite, e.g. delta_n=1e300). */
int af_online_discretise(AfOnline *est, double Ts, char *message, size_t size);

/* One sample: gyr (rad/s) over the last Ts s, acc (m/s^2) and mag (uT; a NaN or all 0: no field
 * sample) now. 1: taken (the outputs are new); 0: not taken, the estimate held (an input not
 * finite or beyond every IMU's range, blocks.pipeline.causal.valid_sample, or an accelerometer
 * all 0 before the start); -1: error with a message (af_online_discretise's). */
int af_online_step(AfOnline *est, const double gyr[3], const double acc[3], const double mag[3], double Ts,
                   char *message, size_t size);

#endif
