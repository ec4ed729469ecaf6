/* causal.h: the causal pipeline, its stages in their order and what each hands the next.
 * Python twin: blocks/pipeline/causal.py.
 *
 *   gyr, acc -> 1 sample timing -> 2 gyro offset -> 3 method -> 4 heading -> 5 latency -> q, g
 *                                                               ^ mag
 *
 * Units: rad/s, m/s^2, uT, s; q sensor -> earth [w, x, y, z]. Parameter values are arrays of
 * AF_N_PARAMS doubles indexed by AF_P_<name> (af_params.h, generated), NaN: not given. */
#ifndef AF_CAUSAL_H
#define AF_CAUSAL_H

#include <stddef.h>

#include "af_params.h"
#include "methods/registry.h"
#include "stages/gyro_offset.h"
#include "stages/heading.h"

/* beyond these no IMU measures (the widest MEMS ranges, per axis): a sample beyond them is not taken */
#define MAX_GYR_RAD_S (4000.0 * (3.14159265358979323846 / 180.0)) /* math.radians(4000.0) */
#define MAX_ACC_M_S2 (400.0 * 9.80665)

/* Pipeline: a configuration of the stages, validated by causal_configure. */
typedef struct {
    AfMethod method;               /* the method, its parameters resolved */
    int offset_runs, heading_runs; /* whether the gyro-offset and heading estimators run */
    double offset_params[AF_N_PARAMS], heading_params[AF_N_PARAMS]; /* theirs, resolved */
    double latency;                /* s */
    int point_gyr, mean_acc;       /* gyr_samples "point", acc_samples "mean" (blocks.stages.timing) */
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
    int has_last_gyr;    /* 1: last_gyr holds the gyro point sample before the next */
    double last_gyr[3];  /* rad/s */
    int started;         /* 1 once the stages started (Python: the method's state is not None) */
    double offset[GYRO_OFFSET_STATE_SIZE];
    double method[AF_STEPPER_STATE_MAX];
    double heading[HEADING_STATE_SIZE];
} AfState;

/* Rows for one sample: the pipeline's outputs after it. */
typedef struct {
    double gravity[3];         /* m/s^2, sensor coordinates, after latency */
    double quat[4];            /* sensor -> earth, after latency */
    double offset[3];          /* the gyro-offset estimate (rad/s), where that stage runs */
    double offset_variance[3]; /* its variance per axis ((rad/s)^2) */
    int mag_accepted;          /* where the heading stage runs: whether the field sample was used */
    double mag_offset[3];      /* the hard-iron offset (the field's unit) */
    double mag_delay;          /* the magnetometer's delay allowed for (s) */
} AfRow;

/* valid_sample: whether gyr (rad/s) and acc (m/s^2) are finite and within MAX_GYR_RAD_S, MAX_ACC_M_S2 per axis. */
int valid_sample(const double gyr[3], const double acc[3]);

/* split_params: the given values split into the method's (own), the gyro-offset estimator's and
 * the heading estimator's (NaN where not given); offset and mag say whether those two run. A
 * value goes to every running stage that has its name; a name no running stage has is refused
 * with Python's message. 0, or -1 with the message. */
int split_params(int method, const double given[AF_N_PARAMS], int offset, int mag, double own[AF_N_PARAMS],
                 double offset_given[AF_N_PARAMS], double heading_given[AF_N_PARAMS], char *message, size_t size);

/* configure: the pipeline of `attitude estimate` (method by name, params by index, whether the
 * gyro-offset and heading estimators run, latency s, gyr_samples "mean"/"point", acc_samples
 * "point"/"mean"), every value checked. 0, or -1 with the message of Python's refusal (and a
 * sensor-frame method's design is refused here already, where Python refuses it at the first step). */
int causal_configure(AfPipeline *pipeline, const char *method, const double params[AF_N_PARAMS], int gyro_offset,
                     int heading, double latency, const char *gyr_samples, const char *acc_samples, char *message,
                     size_t size);

/* at: the pipeline discretised for the sample time Ts (s). 0, or -1 with a message: Ts not
 * finite and positive, or a stage's coefficients that overflow at Ts (e.g. delta_n = 1e300). */
int causal_at(const AfPipeline *pipeline, double Ts, AfStep *step, char *message, size_t size);

/* State(): nothing seen yet. */
void causal_initial_state(AfState *state);

/* run for one row: gyr (rad/s), acc (m/s^2), finite, and where the heading stage runs mag (uT;
 * a NaN, or all 0: no field sample) through stages 1-5, state carried on; the first row starts
 * the stages at rest on it (the method's on start_gravity). */
void causal_run(const AfPipeline *pipeline, const AfStep *step, AfState *state, const double gyr[3],
                const double acc[3], const double mag[3], AfRow *out);

#endif
