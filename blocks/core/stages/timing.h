/* timing.h: sample timing: the gyro's and the accelerometer's sample conventions, latency
 * compensation, and when two sample times are one; documented in blocks/stages/timing.py.
 * Units: rad/s, m/s^2, s. */
#ifndef AF_TIMING_H
#define AF_TIMING_H

#include <stddef.h>

#include "quaternion.h"

/* relative difference below which two sample times are one (a master's rounding noise) */
#define STEP_TOLERANCE 1e-9
#define MAX_LATENCY_S 0.5 /* s: the gyro's last rate is no guide to the orientation further ahead */

/* the gyro's sample conventions and the accelerometer's, the convention's first */
extern const char *const GYR_SAMPLES[2];
extern const char *const ACC_SAMPLES[2];

/* 0, or -1 with the message unless gyr_samples is one of GYR_SAMPLES and acc_samples one of ACC_SAMPLES. */
int check_samples(const char *gyr_samples, const char *acc_samples, char *message, size_t size);

/* Whether the sample time Ts (s) is reference (s) up to STEP_TOLERANCE. */
int same_step(double Ts, double reference);

/* a sample grid's instant this many samples past a step's end counts as reached (a master that sums its
 * steps ends 60 s of 0.01 s at 59.99999999999663), this many past its start as passed */
#define GRID_TOLERANCE 1e-6
#define GRID_MAX_SAMPLES 1048576.0 /* samples one communication step may run: a bound on one call's work */

/* The instants start + k*Ts (s, k >= 1) of a sample grid that a communication step from t over h (s)
 * reaches, up to GRID_TOLERANCE: how many samples an FMU with the sample time Ts runs in the step, its
 * inputs held (none: its state and outputs held). Ts finite and positive; t and t + h finite. */
double grid_samples(double start, double Ts, double t, double h);

/* The grid's instant start + k*Ts (s) at t or, up to GRID_TOLERANCE, last before it: where the samples a step
 * from t runs begin (the first ends one Ts later). */
double grid_before(double start, double Ts, double t);

/* The mean rate over the sample time between two point samples of it (rad/s): the trapezoid. */
Vec3 interval_mean(Vec3 before, Vec3 now);

/* 0, or -1 with the message unless latency (s) is finite and within +-MAX_LATENCY_S. */
int check_latency(double latency, char *message, size_t size);

/* q (sensor -> earth) carried forward over latency (s) at the rate gyr (rad/s), q (x) exp(gyr
 * latency), into *q_out; and up (any length) in the sensor frame latency seconds later, into *up_out. */
void carry_forward(Quat q, Vec3 up, Vec3 gyr, double latency, Quat *q_out, Vec3 *up_out);

/* acc (m/s^2), a mean over the sample time Ts (s), in the sensor frame at its end: turned as
 * carry_forward turns the up-vector over Ts/2 at the sample's mean rate gyr (rad/s). */
Vec3 interval_end(Vec3 gyr, Vec3 acc, double Ts);

/* carry_forward on n rows in place: quat (rows of 4) and gravity (rows of 3), at the rates gyr (rows of 3). */
void carry_forward_rows(size_t n, double *quat, double *gravity, const double *gyr, double latency);

/* interval_end on n rows: acc (rows of 3) at the rates gyr (rows of 3) into out (rows of 3). */
void interval_ends(size_t n, const double *gyr, const double *acc, double Ts, double *out);

#endif
