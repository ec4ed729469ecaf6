/* registry.c: Python twin blocks/methods/registry.py (METHODS, method, Method.resolve,
 * runs_kernel, Method.filter, stepper, KernelStepper and SensorFrameStepper). */
#include "registry.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "filters/tseng.h"
#include "messages.h"
#include "methods/luinge.h"
#include "methods/mahony.h"
#include "methods/tseng_adaptive.h"
#include "methods/wiener_local.h"
#include "params.h"

typedef char state_fits[AF_STEPPER_STATE_MAX >= TSENG_ADAPTIVE_STATE_SIZE &&
                                AF_STEPPER_STATE_MAX >= WIENER_LOCAL_STATE_SIZE &&
                                AF_STEPPER_STATE_MAX >= SENSOR_FRAME_STATE_SIZE(MAX_ORDER)
                            ? 1
                            : -1];
typedef char coef_fits[AF_STEPPER_COEF_MAX >= TSENG_ADAPTIVE_COEF_SIZE ? 1 : -1];

int method_index(const char *name, char *message, size_t size)
{
    char available[256] = "", text[128];
    int i;
    for (i = 0; name != NULL && i < AF_N_METHODS; i++)
        if (strcmp(name, AF_STAGES[i].name) == 0) return i;
    for (i = 0; i < AF_N_METHODS; i++) {
        if (i > 0) strcat(available, ", ");
        strcat(available, AF_STAGES[i].name);
    }
    return refuse(message, size, "unknown method %s; available: %s",
                  name != NULL ? str_repr(name, text, sizeof text) : "None", available);
}

/* design_delta_v and _omega_g: the break frequency of the stationary filter */
static int stationary_omega_g(const double *p, double *out, char *message, size_t size)
{
    if (!isnan(p[AF_P_omega_g])) {
        *out = p[AF_P_omega_g];
        return 0;
    }
    return omega_g(p[AF_P_delta_n], isnan(p[AF_P_delta_v]) ? NOMINAL_DELTA_V : p[AF_P_delta_v], p[AF_P_g], out,
                   message, size);
}

/* _wiener_is_local: whether `wiener` runs its local kernel (resolve_params took a stationary of 0 or 1 only) */
static int wiener_is_local(const double *p)
{
    return p[AF_P_stationary] == 0.0 && isnan(p[AF_P_omega_g]) && isnan(p[AF_P_omega_c]) && isnan(p[AF_P_delta_v]);
}

/* the design of each sensor-frame method: _design_wiener, _design_first_order, tseng's */
static int design(int method, const double *p, EarthFilter *f, char *message, size_t size)
{
    double wg, wf;
    switch (method) {
    case AF_STAGE_wiener:
        if (stationary_omega_g(p, &wg, message, size)) return -1;
        return isnan(p[AF_P_omega_c]) ? butterworth(wg, f, message, size)
                                      : wiener_band_limited(wg, p[AF_P_omega_c], f, message, size);
    case AF_STAGE_first_order:
        if (!isnan(p[AF_P_omega_f])) return first_order(p[AF_P_omega_f], f, message, size);
        if (stationary_omega_g(p, &wg, message, size) ||
            best_first_order_cutoff(wg, p[AF_P_omega_c], &wf, message, size))
            return -1;
        return first_order(wf, f, message, size);
    default: /* AF_STAGE_tseng */
        tseng_earth_filter(f);
        return 0;
    }
}

/* the method's resolved parameters as "name = value, ..." for a message */
static void params_text(const AfMethod *m, char *out, size_t size)
{
    const AfStage *stage = &AF_STAGES[m->method];
    char value[FLOAT_REPR_SIZE];
    size_t used = 0;
    int i;
    out[0] = '\0';
    for (i = 0; i < stage->n_params && used < size; i++) {
        double v = m->params[stage->params[i].index];
        if (isnan(v)) continue;
        used += (size_t)snprintf(out + used, size - used, "%s%s = %s", used ? ", " : "", stage->params[i].name,
                                 float_repr(v, value));
    }
}

static int finite_values(const double *values, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(values[i])) return 0;
    return 1;
}

int method_configure(AfMethod *m, int index, const double given[AF_N_PARAMS], char *message, size_t size)
{
    char text[512];
    memset(m, 0, sizeof *m);
    m->method = index;
    if (resolve_params(index, given, m->params, message, size)) return -1;
    switch (index) {
    case AF_STAGE_wiener:
        m->kernel = wiener_is_local(m->params) ? KERNEL_WIENER_LOCAL : KERNEL_NONE;
        break;
    case AF_STAGE_tseng_adaptive: m->kernel = KERNEL_TSENG_ADAPTIVE; break;
    case AF_STAGE_luinge: m->kernel = KERNEL_LUINGE; break;
    case AF_STAGE_mahony: m->kernel = KERNEL_MAHONY; break;
    default: m->kernel = KERNEL_NONE;
    }
    if (m->kernel != KERNEL_NONE) return 0;
    if (design(index, m->params, &m->filter, message, size)) return -1;
    if (!(finite_values(m->filter.A, m->filter.n * m->filter.n) && finite_values(m->filter.B, m->filter.n) &&
          finite_values(m->filter.C, m->filter.n) && isfinite(m->filter.D))) {
        params_text(m, text, sizeof text);
        return refuse(message, size, "%s: the earth-frame filter's coefficients overflow (%s)", AF_STAGES[index].owner,
                      text);
    }
    return 0;
}

/* the kernels (KernelStepper): their state and coefficient sizes, initial_state and run */
static const struct {
    int state_size, coef_size;
    void (*initial_state)(const double *coef, const double *gravity, double *state);
    void (*run)(double *state, const double *coef, const double *gyr, const double *acc, double *gravity,
                double *quat);
} KERNELS[] = {
    [KERNEL_WIENER_LOCAL] = {WIENER_LOCAL_STATE_SIZE, WIENER_LOCAL_COEF_SIZE, wiener_local_initial_state,
                             wiener_local_run},
    [KERNEL_TSENG_ADAPTIVE] = {TSENG_ADAPTIVE_STATE_SIZE, TSENG_ADAPTIVE_COEF_SIZE, tseng_adaptive_initial_state,
                               tseng_adaptive_run},
    [KERNEL_LUINGE] = {LUINGE_STATE_SIZE, LUINGE_COEF_SIZE, luinge_initial_state, luinge_run},
    [KERNEL_MAHONY] = {MAHONY_STATE_SIZE, MAHONY_COEF_SIZE, mahony_initial_state, mahony_run},
};

int stepper_at(AfStepper *s, const AfMethod *m, double Ts, char *message, size_t size)
{
    char text[512], value[FLOAT_REPR_SIZE];
    int finite;
    memset(s, 0, sizeof *s);
    s->kernel = m->kernel;
    s->Ts = Ts;
    if (!(isfinite(Ts) && Ts > 0))
        return refuse(message, size, "sample time Ts must be a finite positive number of seconds, got %s",
                      float_repr(Ts, value));
    if (m->kernel == KERNEL_NONE) {
        if (discrete_filter(&m->filter, Ts, &s->disc, message, size)) return -1;
        s->state_size = SENSOR_FRAME_STATE_SIZE(s->disc.n);
        finite = finite_values(s->disc.Ad, s->disc.n * s->disc.n) && finite_values(s->disc.Bd, s->disc.n);
    } else {
        if (m->kernel == KERNEL_TSENG_ADAPTIVE) {
            if (tseng_adaptive_coefficients(m->params, Ts, s->coef, message, size)) return -1;
        } else if (m->kernel == KERNEL_WIENER_LOCAL) {
            wiener_local_coefficients(m->params, Ts, s->coef);
        } else if (m->kernel == KERNEL_LUINGE) {
            luinge_coefficients(m->params, Ts, s->coef);
        } else if (mahony_coefficients(m->params, Ts, s->coef, message, size)) {
            return -1;
        }
        s->state_size = KERNELS[m->kernel].state_size;
        finite = finite_values(s->coef, KERNELS[m->kernel].coef_size);
    }
    if (finite) return 0;
    params_text(m, text, sizeof text);
    return refuse(message, size, "%s at Ts = %g s: its coefficients overflow (%s)", AF_STAGES[m->method].owner, Ts,
                  text);
}

void stepper_initial_state(const AfStepper *s, const double gravity[3], double *state)
{
    if (s->kernel == KERNEL_NONE)
        sensor_frame_initial_state(&s->disc, gravity, state);
    else
        KERNELS[s->kernel].initial_state(s->coef, gravity, state);
}

void stepper_run(const AfStepper *s, double *state, const double gyr[3], const double acc[3], double gravity[3],
                 double quat[4])
{
    const DiscreteFilter *d = &s->disc;
    if (s->kernel != KERNEL_NONE) {
        KERNELS[s->kernel].run(state, s->coef, gyr, acc, gravity, quat);
        return;
    }
    sensor_frame_step(state, state + 3 * d->n, gyr, acc, d->n, d->Ad, d->Bd, d->C, d->D, d->Ts, gravity);
    quat_store(quat_load(state + 3 * d->n), quat);
}
