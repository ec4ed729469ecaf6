/* causal.h: the causal pipeline, its stages in their order and what each hands the next;
 * driven one sample at a time (pipeline/online.h, an FMU's doStep) or over whole arrays
 * (causal_run_rows; the batch path of blocks.pipeline.batch runs a range of the stages over a
 * range of rows, causal_run_stages, on each of two threads: bindings/threads.cpp).
 *
 *   gyr, acc -> 1 sample timing -> 2 gyro offset -> 3 method -> 4 heading -> 5 latency -> q, g
 *                                                               ^ mag
 *
 * Units: rad/s, m/s^2, uT, s; q sensor -> earth [w, x, y, z]. Parameter values are given by
 * name (params.h: AfGiven) and resolved into arrays of AF_N_PARAMS doubles indexed by
 * AF_P_<name> (af_params.h, generated). */
#ifndef AF_CAUSAL_H
#define AF_CAUSAL_H

#include <stddef.h>

#include "af_params.h"
#include "methods/registry.h"
#include "params.h"
#include "quaternion.h"
#include "stages/gyro_offset.h"
#include "stages/heading.h"

/* beyond these no IMU measures (the widest MEMS ranges, per axis): a sample beyond them is not taken */
#define MAX_GYR_RAD_S (4000.0 * (AF_PI / 180.0)) /* math.radians(4000.0) */
#define MAX_ACC_M_S2 (400.0 * 9.80665)

/* Pipeline: a configuration of the stages, validated by causal_configure. */
typedef struct {
    AfMethod method;               /* the method, its parameters resolved */
    int offset_runs, heading_runs; /* whether the gyro-offset and heading estimators run */
    double offset_params[AF_N_PARAMS], heading_params[AF_N_PARAMS]; /* theirs, resolved */
    double latency;                /* s */
    int point_gyr, mean_acc;       /* gyr_samples "point", acc_samples "mean" (stages/timing.h) */
} AfPipeline;

/* Step: the pipeline's coefficients at one sample time Ts (s). */
typedef struct {
    double Ts;
    AfStepper stepper;
    AfGyroOffsetCoef offset_coef;
    AfHeadingCoef heading_coef;
} AfStep;

/* State: what the stages carry from one sample to the next; each part is read and written by
 * its stage only (sample timing: has_last_gyr, last_gyr; the method: started, method). */
typedef struct {
    int has_last_gyr;    /* 1: last_gyr holds the gyro point sample before the next */
    double last_gyr[3];  /* rad/s */
    int started;         /* 1 once the stages started on a first sample */
    AfGyroOffset offset;
    double method[AF_STEPPER_STATE_MAX]; /* the method's stepper's state (registry.h) */
    AfHeading heading;
} AfState;

/* the stages in their order (causal_run_stages runs a range of them) */
enum { CAUSAL_TIMING, CAUSAL_OFFSET, CAUSAL_METHOD, CAUSAL_HEADING, CAUSAL_LATENCY, CAUSAL_STAGES };

#define CAUSAL_CHUNK 64 /* rows causal_run_rows hands each stage in turn */

/* Row: the pipeline's outputs for one sample. */
typedef struct {
    double gravity[3];         /* m/s^2, sensor coordinates, after latency */
    double quat[4];            /* sensor -> earth, after latency */
    double offset[3];          /* the gyro-offset estimate (rad/s), where that stage runs */
    double offset_variance[3]; /* its variance per axis ((rad/s)^2) */
    int mag_accepted;          /* where the heading stage runs: whether the field sample was used */
    double mag_offset[3];      /* the hard-iron offset (the field's unit) */
    double mag_delay;          /* the magnetometer's delay allowed for (s) */
} AfRow;

/* Rows: where causal_run_rows writes the outputs of n samples, row-major; but for gravity and
 * quat, NULL where not wanted (those of a stage that does not run are never written). */
typedef struct {
    double *gravity;                  /* n x 3 */
    double *quat;                     /* n x 4 */
    double *offset, *offset_variance; /* n x 3 */
    unsigned char *mag_accepted;      /* n: 1 where the field sample was used */
    double *mag_offset;               /* n x 3 */
    double *mag_delay;                /* n */
} AfRows;

/* Inputs: the rows a run takes, row 0 first: gyr, acc (n x 3, finite) and, where the heading
 * stage runs, mag (n x 3; NULL: no field samples); initial_gravity as causal_run_rows. */
typedef struct {
    const double *gyr, *acc, *mag;
    const double *initial_gravity;
} AfInputs;

/* Handover: what stages 1 and 2 hand the method and the latency stage for a range of rows (its
 * first row first): gyr after timing with the offset removed (rad/s) and acc after timing
 * (m/s^2), 3 values a row each. */
typedef struct {
    double *gyr, *acc;
} AfHandover;

/* valid_sample: whether gyr (rad/s) and acc (m/s^2) are finite and within MAX_GYR_RAD_S, MAX_ACC_M_S2 per axis. */
int valid_sample(const double gyr[3], const double acc[3]);

/* split_params: the n given values split into the method's (own), the gyro-offset estimator's
 * and the heading estimator's, each in its stage's order of parameters (AF_N_PARAMS entries
 * each at most; n_own, n_offset, n_heading their counts); offset and mag say whether those two
 * run. A value goes to every running stage that has its name; the first name no running stage
 * has is refused: "unknown parameter 'x' (the method wiener: delta_n, ...; the gyro-offset
 * estimator: ...)". 0, or -1 with the message. */
int split_params(int method, const AfGiven *given, int n, int offset, int mag, AfGiven *own, int *n_own,
                 AfGiven *offset_given, int *n_offset, AfGiven *heading_given, int *n_heading, char *message,
                 size_t size);

/* configure: the pipeline of `attitude estimate` (method by name, n params given by name, whether
 * the gyro-offset and heading estimators run, latency s, gyr_samples "mean"/"point",
 * acc_samples "point"/"mean"), every value checked in this order: the method's name, the
 * parameters' names (split_params), the method's values and its design (method_configure), the
 * gyro-offset and heading estimators' values, the sample conventions, the latency. 0, or -1
 * with the message of the first refused. */
int causal_configure(AfPipeline *pipeline, const char *method, const AfGiven *params, int n, int gyro_offset,
                     int heading, double latency, const char *gyr_samples, const char *acc_samples, char *message,
                     size_t size);

/* at: the pipeline discretised for the sample time Ts (s), the method's filter held by zoh
 * (NULL: the core's own, registry.h). 0, or -1 with a message: Ts not finite and positive
 * ("sample time must be a finite positive number of seconds, got ..."), or a stage's coefficients that overflow at Ts (e.g. delta_n = 1e300). */
int causal_at(const AfPipeline *pipeline, double Ts, const AfZoh *zoh, AfStep *step, char *message, size_t size);

/* State(): nothing seen yet. */
void causal_initial_state(AfState *state);

/* run for one row: gyr (rad/s), acc (m/s^2), finite, and where the heading stage runs mag (uT;
 * a NaN, or all 0: no field sample) through stages 1-5, state carried on; the first row starts
 * the stages at rest on it (the method's on start_gravity). */
void causal_run(const AfPipeline *pipeline, const AfStep *step, AfState *state, const double gyr[3],
                const double acc[3], const double mag[3], AfRow *out);

/* run over n rows gyr, acc (n x 3, finite) and, where the heading stage runs, mag (n x 3; NULL:
 * no field samples): as causal_run on each (the stages take CAUSAL_CHUNK rows at a time, one
 * after another), the outputs into out. Where the stages start on the first row, the method
 * starts at rest on initial_gravity (m/s^2, sensor coordinates, before the first sample) if not
 * NULL, else on start_gravity of that row. */
void causal_run_rows(const AfPipeline *pipeline, const AfStep *step, AfState *state, size_t n, const double *gyr,
                     const double *acc, const double *mag, const double initial_gravity[3], const AfRows *out);

/* stage_runs: whether the stage (CAUSAL_*) runs in the pipeline (sample timing and the method always do). */
int causal_stage_runs(const AfPipeline *pipeline, int stage);

/* copy_stages: the parts of from's state that the stages [first, last) (CAUSAL_*) carry, into to. */
void causal_copy_stages(AfState *to, const AfState *from, int first, int last);

/* run_stages: rows [i, j) of in (and of out, row 0 first) through the stages [first, last)
 * (CAUSAL_*) that run, the hand-over of rows [i, j) in handover (written by stages 1 and 2, read
 * by 3 and 5); starts: whether row i is the first the stages see (they start on it as in
 * causal_run_rows). causal_run_rows is this over chunks of rows and every stage. A stage touches
 * its part of state (causal_copy_stages), its outputs of rows [i, j) and the hand-over only:
 * the stages from some stage on may run over rows on one thread while those before it run
 * over later rows on another, the rows' hand-over and outputs written before they are handed on. */
void causal_run_stages(const AfPipeline *pipeline, const AfStep *step, AfState *state, int first, int last,
                       size_t i, size_t j, int starts, const AfInputs *in, const AfHandover *handover,
                       const AfRows *out);

#endif
