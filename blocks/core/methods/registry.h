/* registry.h: the estimator methods by name, their parameters, and their per-sample step.
 * A method is an earth-frame LTI filter carried into the sensor frame (filters/sensor_frame.h)
 * or a kernel of its own (wiener_local, luinge, mahony, tseng_adaptive); either is driven
 * through an AfStepper: its coefficients a struct per kind, its state an array of doubles (the
 * python-control block's state vector) that holds the kernel's state struct. Resolved parameter
 * values are arrays of AF_N_PARAMS doubles indexed by AF_P_<name> (af_params.h, generated). */
#ifndef AF_REGISTRY_H
#define AF_REGISTRY_H

#include <stddef.h>

#include "af_params.h"
#include "filters/earth_filters.h"
#include "filters/sensor_frame.h"
#include "methods/luinge.h"
#include "methods/mahony.h"
#include "methods/tseng_adaptive.h"
#include "methods/wiener_local.h"
#include "params.h"

#define NOMINAL_DELTA_V 1.0 /* m/s/sqrt(Hz): the slosh the stationary filter assumes when delta_v is unset */

/* What a method runs: its earth filter in the sensor frame, or a kernel. */
enum { KERNEL_NONE, KERNEL_WIENER_LOCAL, KERNEL_TSENG_ADAPTIVE, KERNEL_LUINGE, KERNEL_MAHONY, KERNEL_COUNT };

/* the kernels' names, by KERNEL_<name>: "sensor_frame", "wiener_local", ... */
extern const char *const KERNEL_NAMES[KERNEL_COUNT];

#define AF_STEPPER_STATE_MAX 22 /* doubles in the largest state of any method: tseng_adaptive's */
#define STATE_NAME_SIZE 8       /* bytes that hold any state value's name */

/* A method with its parameters, validated. */
typedef struct {
    int method;                 /* AF_STAGE_<name>, below AF_N_METHODS */
    int kernel;                 /* KERNEL_NONE: the sensor-frame filter; else the kernel that runs */
    double params[AF_N_PARAMS]; /* resolved: defaults and given values; NaN: unset (None) or not the method's */
    EarthFilter filter;         /* the core's design of the earth-frame filter it runs (KERNEL_NONE and
                                   KERNEL_TSENG_ADAPTIVE) */
} AfMethod;

/* The method's step at one sample time: a discretised sensor-frame filter or a kernel's
 * coefficients. Plain data. Its state is an array of state_size doubles: a sensor-frame
 * filter's rows X (n x 3) then q, or the kernel's state struct (WienerLocalState, ...). */
typedef struct {
    int kernel;     /* as AfMethod.kernel */
    double Ts;      /* s */
    int state_size; /* doubles in the stepper's state */
    union {
        DiscreteFilter sensor_frame; /* KERNEL_NONE: the filter at Ts */
        WienerLocalCoef wiener_local;
        TsengAdaptiveCoef tseng_adaptive;
        LuingeCoef luinge;
        MahonyCoef mahony;
    } coef;
} AfStepper;

typedef char states_fit[AF_STEPPER_STATE_MAX * sizeof(double) >= sizeof(WienerLocalState) &&
                                AF_STEPPER_STATE_MAX * sizeof(double) >= sizeof(TsengAdaptiveState) &&
                                AF_STEPPER_STATE_MAX * sizeof(double) >= sizeof(LuingeState) &&
                                AF_STEPPER_STATE_MAX * sizeof(double) >= sizeof(MahonyState) &&
                                AF_STEPPER_STATE_MAX >= SENSOR_FRAME_STATE_SIZE(MAX_ORDER)
                            ? 1
                            : -1];

/* Where a method's discrete filter comes from: a caller's zero-order hold of the earth filter
 * the method runs, at the sample time Ts (s), into *out: 0, or -1 with a message. The Python
 * package designs its filters with python-control and hands down control.c2d's. Where no
 * AfZoh is given (NULL), the core holds its own design (discrete_filter). */
typedef struct {
    int (*hold)(void *context, double Ts, DiscreteFilter *out, char *message, size_t size);
    void *context;
} AfZoh;

/* The index AF_STAGE_<name> of a method, or -1 with "unknown method 'x'; available: wiener,
 * tseng, ..." (name NULL: shown as None). */
int method_index(const char *name, char *message, size_t size);

/* The method of index with the n values given (by name, in that order): resolved (params.h:
 * resolve_given, its refusals and messages), what it runs decided and, where that is an earth
 * filter, the core's design of it made (with the design's refusals, e.g. omega_c too low for
 * eq. 33, and a filter whose coefficients overflow). 0, or -1 with a message. */
int method_configure(AfMethod *m, int index, const AfGiven *given, int n, char *message, size_t size);

/* The method's step at the sample time Ts (s), for any Ts, its filter held by zoh (NULL: the
 * core's own). 0, or -1 with a message: Ts not finite and positive ("sample time Ts must be a
 * finite positive number of seconds, got ..."), Mahony gains that diverge at Ts (`mahony` and
 * `tseng_adaptive`: mahony_check_gains), zoh's refusal, or coefficients that overflow at Ts;
 * call it once with the nominal Ts at initialisation to refuse such parameters there. */
int stepper_at(AfStepper *s, const AfMethod *m, double Ts, const AfZoh *zoh, char *message, size_t size);

/* The sensor-frame step of any earth filter held over d->Ts (s): 0, or -1 with a message where
 * its order exceeds MAX_ORDER or Ts is not finite and positive. */
int stepper_of_filter(AfStepper *s, const DiscreteFilter *d, char *message, size_t size);

/* The names of the stepper's state values, in order (s->state_size of them, each below
 * STATE_NAME_SIZE bytes): x0_x, x0_y, ..., q_w, ... of a sensor-frame filter, a kernel's own. */
void stepper_state_names(const AfStepper *s, char names[][STATE_NAME_SIZE]);

/* Whether state (s->state_size doubles; s a stepper the core made) is one the stepper can run on:
 * finite, its quaternion (q_w ... q_z, where it has one) a unit one to 1e-6. */
int stepper_state_valid(const AfStepper *s, const double *state);

/* initial_state(gravity): at rest on gravity (m/s^2, sensor coordinates; e.g. start_gravity
 * of the first sample), into state (s->state_size values). */
void stepper_initial_state(const AfStepper *s, const double gravity[3], double *state);

/* run on one sample: gyr (rad/s, mean over the sample), acc (m/s^2) now; state in place;
 * writes the gravity estimate (m/s^2, sensor coordinates) and q (sensor -> earth). */
void stepper_run(const AfStepper *s, double *state, const double gyr[3], const double acc[3], double gravity[3],
                 double quat[4]);

/* stepper_run over n rows: gyr, acc (n x 3); gravity (n x 3) and quat (n x 4) written (wiener's
 * local densities pass by pass over blocks of rows, wiener_local_rows). */
void stepper_run_rows(const AfStepper *s, double *state, size_t n, const double *gyr, const double *acc,
                      double *gravity, double *quat);

#endif
