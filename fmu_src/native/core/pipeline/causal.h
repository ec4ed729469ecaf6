/* causal.h: the causal pipeline, its stages in their order and what each hands the next.
 * Python twin: blocks/pipeline/causal.py.
 *   gyr, acc -> 1 sample timing -> 2 gyro offset -> 3 method -> 4 heading -> 5 latency -> q, g */
#ifndef AF_CAUSAL_H
#define AF_CAUSAL_H

#include <stddef.h>

#include "af_params.h"
#include "stages/gyro_offset.h"
#include "stages/heading.h"

/* stand-in for the method's stepper until methods/registry.h is in */
#ifndef AF_STEPPER_STATE_MAX
#define AF_STEPPER_STATE_MAX 64
typedef struct { int method; double coef[512]; } AfStepper;
#endif

#define MAX_GYR_RAD_S (4000.0 * 0.017453292519943295) /* beyond these no IMU measures (per axis) */
#define MAX_ACC_M_S2 (400.0 * 9.80665)

/* Pipeline: a configuration of the stages, validated by af_configure. */
typedef struct {
    int method;                    /* index of the method (methods/registry.h) */
    double params[AF_N_PARAMS];    /* the method's parameters as given (NaN: not given) */
    int offset_runs, heading_runs; /* whether the gyro-offset and heading stages run */
    double offset_params[AF_N_PARAMS], heading_params[AF_N_PARAMS]; /* their parameters, resolved */
    double latency;                /* s */
    int point_gyr, mean_acc;       /* the sample conventions (blocks.stages.timing) */
} AfPipeline;

/* Step: the pipeline's coefficients at one sample time Ts (s). */
typedef struct {
    double Ts;
    AfStepper stepper;
    double offset_coef[GYRO_OFFSET_COEF_SIZE];
    double heading_coef[HEADING_COEF_SIZE];
} AfStep;

/* State: what the stages carry from one sample to the next. */
typedef struct {
    int has_last_gyr;                /* 1: last_gyr holds the point sample before the next */
    double last_gyr[3];              /* rad/s */
    int started;                     /* 0 until the first sample (the method's state is then set) */
    double offset[GYRO_OFFSET_STATE_SIZE];
    double method[AF_STEPPER_STATE_MAX];
    double heading[HEADING_STATE_SIZE];
} AfState;

/* Valid: whether gyr (rad/s) and acc (m/s^2) are finite and within MAX_GYR_RAD_S, MAX_ACC_M_S2 per axis. */
int valid_sample(const double gyr[3], const double acc[3]);

#endif
