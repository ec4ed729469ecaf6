/* online.h: the causal pipeline one sample at a time (an FMU's doStep; the Python package's
 * OnlineEstimator), the sample time taken from each call.
 * Units: gyr rad/s, acc m/s^2, mag uT, Ts and latency s; q sensor -> earth [w, x, y, z]. */
#ifndef AF_ONLINE_H
#define AF_ONLINE_H

#include <stddef.h>

#include "af_params.h" /* AF_N_PARAMS and AF_P_<name>, the index of every tuning parameter (generated) */
#include "pipeline/causal.h"

/* What the estimator is configured with (an FMU's parameters). */
typedef struct {
    const char *method;         /* "wiener", "first_order", "luinge", "tseng", "tseng_adaptive", "mahony" */
    double params[AF_N_PARAMS]; /* every tuning parameter by its index AF_P_<name>; NaN: not given */
    int heading;                /* 1: the magnetometer's heading stage runs (FMU heading "mag") */
    int gyro_offset;            /* 1: the gyro-offset stage runs */
    double latency;             /* s, within +-MAX_LATENCY_S */
    const char *gyr_samples;    /* "mean" or "point" (stages/timing.h); NULL: "mean" */
    const char *acc_samples;    /* "point" or "mean"; NULL: "point" */
} AfConfig;

/* The whole estimator: configuration, the discretisation at the last Ts, every stage's state
 * and the outputs. Plain data, no pointers: an FMU state is a copy of it. */
typedef struct {
    AfPipeline pipeline;        /* the configuration, validated */
    int discretised;            /* 1: step holds the pipeline at the last sample time */
    AfStep step;
    AfState state;              /* what the stages carry from sample to sample */
    /* the estimate after the last sample taken (held while samples are not taken) */
    double quat[4];             /* sensor -> earth, [w, x, y, z] */
    double up[3];               /* unit up-vector, sensor coordinates */
    double euler[3];            /* roll, pitch, yaw (rad, Z-Y-X) of quat */
    double offset[3];           /* gyro-offset estimate (rad/s; 0 without that stage) */
    double mag_offset[3];       /* hard-iron offset estimate (uT; 0 until one is proven) */
    double mag_delay;           /* the magnetometer's delay the heading allows for (s): the parameter
                                   mag_delay, or its online estimate (0 until one is taken) */
} AfOnline;

/* 0, or -1 with a message (causal_configure's refusals, the parameters given in index order). */
int af_online_init(AfOnline *est, const AfConfig *config, char *message, size_t size);

/* The estimator of a configured pipeline, nothing seen, not discretised. */
void af_online_of(AfOnline *est, const AfPipeline *pipeline);

/* Forget every sample; the configuration and the discretisation stay. */
void af_online_reset(AfOnline *est);

/* The pipeline discretised at Ts (s) now, as a step at Ts would, its method's filter held by
 * zoh (NULL: the core's own): 0, or -1 with a message (Ts not finite and positive, or
 * coefficients that overflow at Ts, e.g. delta_n = 1e300), the last discretisation kept. A
 * model calls it at initialisation with its nominal Ts to refuse such parameters there. */
int af_online_discretise(AfOnline *est, double Ts, const AfZoh *zoh, char *message, size_t size);

/* One sample: gyr (rad/s) over the last Ts s, acc (m/s^2) and mag (uT; a NaN or all 0: no field
 * sample; read only where the heading stage runs) now. A Ts within STEP_TOLERANCE of the last
 * one keeps its discretisation; another is discretised with zoh (NULL: the core's own).
 * 1: taken (the outputs are new); 0: not taken, the estimate held (a gyro or accelerometer
 * value not finite or beyond every IMU's range, valid_sample; or an accelerometer all 0 before
 * the start; a finite gyro point sample still counts as the one before the next);
 * -1: error with af_online_discretise's message. */
int af_online_step_with(AfOnline *est, const double gyr[3], const double acc[3], const double mag[3], double Ts,
                        const AfZoh *zoh, char *message, size_t size);

/* Whether est (bytes nobody vouches for, e.g. an FMU state's) is an estimator of the configuration
 * configured (af_online_init's from the same parameters, not discretised) that can step: its
 * pipeline configured's, bit for bit; its discretisation (if any) the core's own of that pipeline at
 * its Ts; every flag 0 or 1; the stages' states and the outputs finite; the method's quaternion a
 * unit one once started. 0, or -1 with the first field refused in message. */
int af_online_validate(const AfOnline *est, const AfOnline *configured, char *message, size_t size);

/* af_online_step_with the core's own discretisation. */
int af_online_step(AfOnline *est, const double gyr[3], const double acc[3], const double mag[3], double Ts,
                   char *message, size_t size);

#endif
