/* registry.h: the estimator methods by name, their parameters, and their per-sample step.
 * Python twin: blocks/methods/registry.py. A method is an earth-frame LTI filter carried into
 * the sensor frame (filters/sensor_frame.h) or a kernel of its own (wiener_local, luinge,
 * mahony, tseng_adaptive); either is driven through an AfStepper. States and coefficients
 * are plain double arrays in the Python twin's layout. Parameter values are arrays of
 * AF_N_PARAMS doubles indexed by AF_P_<name> (af_params.h, generated), NaN: not given. */
#ifndef AF_REGISTRY_H
#define AF_REGISTRY_H

#include <stddef.h>

#include "af_params.h"
#include "filters/earth_filters.h"
#include "filters/sensor_frame.h"

#define NOMINAL_DELTA_V 1.0 /* m/s/sqrt(Hz): the slosh the stationary filter assumes when delta_v is unset */

/* What a method runs (Method.runs_kernel): its earth filter in the sensor frame, or a kernel. */
enum { KERNEL_NONE, KERNEL_WIENER_LOCAL, KERNEL_TSENG_ADAPTIVE, KERNEL_LUINGE, KERNEL_MAHONY };

#define AF_STEPPER_STATE_MAX 22 /* the largest state of any method: tseng_adaptive's, 3 n + 7 */
#define AF_STEPPER_COEF_MAX (7 + 3 * MAX_ORDER + MAX_ORDER * MAX_ORDER) /* tseng_adaptive's coefficients */

/* A method with its parameters, validated (Python's Method with its resolved values). */
typedef struct {
    int method;                 /* AF_STAGE_<name>, below AF_N_METHODS */
    int kernel;                 /* KERNEL_NONE: the sensor-frame filter; else the kernel that runs */
    double params[AF_N_PARAMS]; /* resolved: defaults and given values; NaN: unset (None) or not the method's */
    EarthFilter filter;         /* the earth-frame filter (KERNEL_NONE) */
} AfMethod;

/* The method's step at one sample time: a discretised sensor-frame filter or a kernel's
 * coefficients. Plain data. */
typedef struct {
    int kernel;                       /* as AfMethod.kernel */
    double Ts;                        /* s */
    int state_size;                   /* values of the stepper's state */
    DiscreteFilter disc;              /* KERNEL_NONE: the filter at Ts */
    double coef[AF_STEPPER_COEF_MAX]; /* a kernel's coefficients (its Python coefficients(params, Ts)) */
} AfStepper;

/* method(name): the index AF_STAGE_<name> of a method, or -1 with Python's message
 * "unknown method 'x'; available: wiener, tseng, ..." (name NULL: Python's None). */
int method_index(const char *name, char *message, size_t size);

/* The method of index with the values given: resolved (Method.resolve: blocks/params.py's
 * refusals and messages: ranges, and a stationary other than 0 or 1), what it runs decided
 * (runs_kernel) and, for a sensor-frame method, its earth filter designed (Method.filter,
 * with the design's refusals, e.g. omega_c too low for eq. 33, and a filter whose coefficients
 * overflow). given: NaN where not given; a value for a name the method lacks is refused.
 * 0, or -1 with a message. */
int method_configure(AfMethod *m, int index, const double given[AF_N_PARAMS], char *message, size_t size);

/* stepper(name, params, Ts): the method's step at the sample time Ts (s), for any Ts (the
 * zero-order hold computed again). 0, or -1 with a message: Ts not finite and positive, Mahony
 * gains that diverge at Ts (`mahony` and `tseng_adaptive`: mahony_check_gains), or coefficients
 * that overflow at Ts; call it once with the nominal Ts at initialisation to refuse such
 * parameters there. */
int stepper_at(AfStepper *s, const AfMethod *m, double Ts, char *message, size_t size);

/* initial_state(gravity): at rest on gravity (m/s^2, sensor coordinates; e.g. start_gravity
 * of the first sample), into state (s->state_size values). */
void stepper_initial_state(const AfStepper *s, const double gravity[3], double *state);

/* run on one sample: gyr (rad/s, mean over the sample), acc (m/s^2) now; state in place;
 * writes the gravity estimate (m/s^2, sensor coordinates) and q (sensor -> earth). */
void stepper_run(const AfStepper *s, double *state, const double gyr[3], const double acc[3], double gravity[3],
                 double quat[4]);

#endif
