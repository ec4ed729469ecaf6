/* registry.c: the methods by name (see registry.h). */
#include "registry.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "filters/tseng.h"
#include "messages.h"

const char *const KERNEL_NAMES[KERNEL_COUNT] = {
    [KERNEL_NONE] = "sensor_frame", [KERNEL_WIENER_LOCAL] = "wiener_local", [KERNEL_TSENG_ADAPTIVE] = "tseng_adaptive",
    [KERNEL_LUINGE] = "luinge", [KERNEL_MAHONY] = "mahony",
};

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

/* whether `wiener` runs its local kernel (resolve_given took a stationary of 0 or 1 only) */
static int wiener_is_local(const double *p)
{
    return p[AF_P_stationary] == 0.0 && isnan(p[AF_P_omega_g]) && isnan(p[AF_P_omega_c]) && isnan(p[AF_P_delta_v]);
}

/* the design of each earth filter a method runs: wiener's stationary filter, first_order's, tseng's (also
 * tseng_adaptive's complementary mode) */
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
    default: /* AF_STAGE_tseng, AF_STAGE_tseng_adaptive */
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

int method_configure(AfMethod *m, int index, const AfGiven *given, int n, char *message, size_t size)
{
    char text[512];
    memset(m, 0, sizeof *m);
    m->method = index;
    if (resolve_given(index, given, n, m->params, message, size)) return -1;
    switch (index) {
    case AF_STAGE_wiener:
        m->kernel = wiener_is_local(m->params) ? KERNEL_WIENER_LOCAL : KERNEL_NONE;
        break;
    case AF_STAGE_tseng_adaptive: m->kernel = KERNEL_TSENG_ADAPTIVE; break;
    case AF_STAGE_luinge: m->kernel = KERNEL_LUINGE; break;
    case AF_STAGE_mahony: m->kernel = KERNEL_MAHONY; break;
    default: m->kernel = KERNEL_NONE;
    }
    if (m->kernel != KERNEL_NONE && m->kernel != KERNEL_TSENG_ADAPTIVE) return 0;
    if (design(index, m->params, &m->filter, message, size)) return -1;
    if (!(finite_values(m->filter.A, m->filter.n * m->filter.n) && finite_values(m->filter.B, m->filter.n) &&
          finite_values(m->filter.C, m->filter.n) && isfinite(m->filter.D))) {
        params_text(m, text, sizeof text);
        return refuse(message, size, "%s: the earth-frame filter's coefficients overflow (%s)", AF_STAGES[index].owner,
                      text);
    }
    return 0;
}

/* the kernels' state names after the filter rows some have (tseng_adaptive's), in order */
static const char *const KERNEL_STATE_NAMES[KERNEL_COUNT][WIENER_LOCAL_STATE_SIZE + 1] = {
    [KERNEL_NONE] = {"q_w", "q_x", "q_y", "q_z", NULL},
    [KERNEL_WIENER_LOCAL] = {"g_x", "g_y", "g_z", "u_x", "u_y", "u_z", "v_x", "v_y", "v_z", "f_x", "f_y", "f_z",
                             "q_w", "q_x", "q_y", "q_z", "w2", "v2", "omega_g", "t", NULL},
    [KERNEL_TSENG_ADAPTIVE] = {"q_w", "q_x", "q_y", "q_z", "b_x", "b_y", "b_z", NULL},
    [KERNEL_LUINGE] = {"q_w", "q_x", "q_y", "q_z", "P_x", "P_y", NULL},
    [KERNEL_MAHONY] = {"q_w", "q_x", "q_y", "q_z", "b_x", "b_y", "b_z", NULL},
};

/* the method's earth filter held over Ts: by zoh, or the core's own; its order checked */
static int hold(const AfMethod *m, double Ts, const AfZoh *zoh, DiscreteFilter *disc, char *message, size_t size)
{
    if (zoh == NULL) return discrete_filter(&m->filter, Ts, disc, message, size);
    memset(disc, 0, sizeof *disc);
    if (zoh->hold(zoh->context, Ts, disc, message, size)) return -1;
    if (disc->n < 0 || disc->n > MAX_ORDER)
        return refuse(message, size, "%s: its earth-frame filter has %d states, at most %d are taken",
                      AF_STAGES[m->method].owner, disc->n, MAX_ORDER);
    disc->Ts = Ts;
    return 0;
}

/* whether every double of a coefficient struct is finite */
#define FINITE_STRUCT(c) finite_values((const double *)&(c), (int)(sizeof(c) / sizeof(double)))

int stepper_at(AfStepper *s, const AfMethod *m, double Ts, const AfZoh *zoh, char *message, size_t size)
{
    char text[512], value[FLOAT_REPR_SIZE];
    int finite;
    memset(s, 0, sizeof *s);
    s->kernel = m->kernel;
    s->Ts = Ts;
    if (!(isfinite(Ts) && Ts > 0))
        return refuse(message, size, "sample time Ts must be a finite positive number of seconds, got %s",
                      float_repr(Ts, value));
    switch (m->kernel) {
    case KERNEL_NONE: {
        DiscreteFilter *d = &s->coef.sensor_frame;
        if (hold(m, Ts, zoh, d, message, size)) return -1;
        s->state_size = SENSOR_FRAME_STATE_SIZE(d->n);
        finite = finite_values(d->Ad, d->n * d->n) && finite_values(d->Bd, d->n);
        break;
    }
    case KERNEL_TSENG_ADAPTIVE: {
        /* its Mahony mode's gains first, then its complementary filter */
        DiscreteFilter d;
        if (mahony_check_gains(m->params[AF_P_k_P], m->params[AF_P_k_I], Ts, message, size) ||
            hold(m, Ts, zoh, &d, message, size))
            return -1;
        if (d.n != TSENG_ORDER)
            return refuse(message, size, "%s: its earth-frame filter has %d states, not %d", AF_STAGES[m->method].owner,
                          d.n, TSENG_ORDER);
        tseng_adaptive_coefficients(m->params, &d, &s->coef.tseng_adaptive);
        s->state_size = sizeof(TsengAdaptiveState) / sizeof(double);
        finite = finite_values(d.Ad, d.n * d.n) && finite_values(d.Bd, d.n) && finite_values(d.C, d.n);
        break;
    }
    case KERNEL_WIENER_LOCAL:
        wiener_local_coefficients(m->params, Ts, &s->coef.wiener_local);
        s->state_size = WIENER_LOCAL_STATE_SIZE;
        finite = FINITE_STRUCT(s->coef.wiener_local);
        break;
    case KERNEL_LUINGE:
        luinge_coefficients(m->params, Ts, &s->coef.luinge);
        s->state_size = sizeof(LuingeState) / sizeof(double);
        finite = FINITE_STRUCT(s->coef.luinge);
        break;
    default: /* KERNEL_MAHONY */
        if (mahony_coefficients(m->params, Ts, &s->coef.mahony, message, size)) return -1;
        s->state_size = sizeof(MahonyState) / sizeof(double);
        finite = FINITE_STRUCT(s->coef.mahony);
    }
    if (finite) return 0;
    params_text(m, text, sizeof text);
    return refuse(message, size, "%s at Ts = %g s: its coefficients overflow (%s)", AF_STAGES[m->method].owner, Ts,
                  text);
}

int stepper_of_filter(AfStepper *s, const DiscreteFilter *d, char *message, size_t size)
{
    char value[FLOAT_REPR_SIZE];
    memset(s, 0, sizeof *s);
    if (!(isfinite(d->Ts) && d->Ts > 0))
        return refuse(message, size, "sample time Ts must be a finite positive number of seconds, got %s",
                      float_repr(d->Ts, value));
    if (d->n < 0 || d->n > MAX_ORDER)
        return refuse(message, size, "the earth-frame filter has %d states, at most %d are taken", d->n, MAX_ORDER);
    s->kernel = KERNEL_NONE;
    s->Ts = d->Ts;
    s->coef.sensor_frame = *d;
    s->state_size = SENSOR_FRAME_STATE_SIZE(d->n);
    return 0;
}

void stepper_state_names(const AfStepper *s, char names[][STATE_NAME_SIZE])
{
    static const char axes[3] = {'x', 'y', 'z'};
    int rows = s->kernel == KERNEL_NONE ? s->coef.sensor_frame.n : s->kernel == KERNEL_TSENG_ADAPTIVE ? TSENG_ORDER : 0;
    int k = 0;
    for (int j = 0; j < rows; j++) /* x<j>_<axis>, j below MAX_ORDER: one digit */
        for (int i = 0; i < 3; i++) {
            char *name = names[k++];
            name[0] = 'x', name[1] = (char)('0' + j), name[2] = '_', name[3] = axes[i], name[4] = '\0';
        }
    for (const char *const *name = KERNEL_STATE_NAMES[s->kernel]; *name != NULL; name++)
        snprintf(names[k++], STATE_NAME_SIZE, "%s", *name);
}

int stepper_state_valid(const AfStepper *s, const double *state)
{
    char names[AF_STEPPER_STATE_MAX][STATE_NAME_SIZE];
    if (s->state_size < 0 || s->state_size > AF_STEPPER_STATE_MAX || !finite_values(state, s->state_size)) return 0;
    stepper_state_names(s, names);
    for (int k = 0; k + 3 < s->state_size; k++)
        if (strcmp(names[k], "q_w") == 0) {
            double n2 = state[k] * state[k] + state[k + 1] * state[k + 1] + state[k + 2] * state[k + 2] +
                        state[k + 3] * state[k + 3];
            return fabs(n2 - 1.0) < 1e-6;
        }
    return 1;
}

/* The stepper's state array as the kernel's state struct (the array is of doubles, as the struct's members) */
#define STATE(type, state) ((type *)(void *)(state))

void stepper_initial_state(const AfStepper *s, const double gravity[3], double *state)
{
    switch (s->kernel) {
    case KERNEL_WIENER_LOCAL:
        wiener_local_initial_state(&s->coef.wiener_local, gravity, STATE(WienerLocalState, state));
        break;
    case KERNEL_TSENG_ADAPTIVE:
        tseng_adaptive_initial_state(&s->coef.tseng_adaptive, gravity, STATE(TsengAdaptiveState, state));
        break;
    case KERNEL_LUINGE: luinge_initial_state(&s->coef.luinge, gravity, STATE(LuingeState, state)); break;
    case KERNEL_MAHONY: mahony_initial_state(&s->coef.mahony, gravity, STATE(MahonyState, state)); break;
    default: sensor_frame_initial_state(&s->coef.sensor_frame, gravity, state);
    }
}

void stepper_run(const AfStepper *s, double *state, const double gyr[3], const double acc[3], double gravity[3],
                 double quat[4])
{
    const DiscreteFilter *d = &s->coef.sensor_frame;
    switch (s->kernel) {
    case KERNEL_WIENER_LOCAL:
        wiener_local_run(STATE(WienerLocalState, state), &s->coef.wiener_local, gyr, acc, gravity, quat);
        break;
    case KERNEL_TSENG_ADAPTIVE:
        tseng_adaptive_run(STATE(TsengAdaptiveState, state), &s->coef.tseng_adaptive, gyr, acc, gravity, quat);
        break;
    case KERNEL_LUINGE: luinge_run(STATE(LuingeState, state), &s->coef.luinge, gyr, acc, gravity, quat); break;
    case KERNEL_MAHONY: mahony_run(STATE(MahonyState, state), &s->coef.mahony, gyr, acc, gravity, quat); break;
    default:
        sensor_frame_step(STATE(Vec3, state), STATE(Quat, state + 3 * d->n), gyr, acc, d->n, d->Ad, d->Bd, d->C,
                          d->D, d->Ts, gravity);
        quat_store(*STATE(Quat, state + 3 * d->n), quat);
    }
}

void stepper_run_rows(const AfStepper *s, double *state, size_t n, const double *gyr, const double *acc,
                      double *gravity, double *quat)
{
    if (s->kernel == KERNEL_WIENER_LOCAL) {
        wiener_local_rows(STATE(WienerLocalState, state), &s->coef.wiener_local, n, gyr, acc, NULL, gravity, quat,
                          NULL);
        return;
    }
    for (size_t k = 0; k < n; k++)
        stepper_run(s, state, gyr + 3 * k, acc + 3 * k, gravity + 3 * k, quat + 4 * k);
}
