/* wiener_local.c: the Wiener filter with local noise densities (see wiener_local.h). */
#include "wiener_local.h"

#include <math.h>

#include <stddef.h>

#include "filters/earth_filters.h"
#include "filters/sensor_frame.h"
#include "quaternion.h"

double band_pass_variance(double omega_m, double tau_v)
{
    double c = omega_m * tau_v;
    return c * c * (2.0 * c + 1.0) / (8.0 * tau_v * pow(c + 1.0, 2.0));
}

void wiener_local_coefficients(const double params[AF_N_PARAMS], double Ts, WienerLocalCoef *coef)
{
    double wm = params[AF_P_omega_m], tau_v = params[AF_P_tau_v];
    *coef = (WienerLocalCoef){
        .Ts = Ts,
        .g = params[AF_P_g],
        .dn2 = pow(params[AF_P_delta_n], 2.0),
        .k_w = 4.0 * pow(params[AF_P_scale_error], 2.0) / wm,
        .inv_J = 1.0 / band_pass_variance(wm, tau_v),
        .dv2_min = pow(params[AF_P_delta_v_min], 2.0),
        .a_avg = 1.0 - exp(-Ts / params[AF_P_tau_noise]),
        .leak_v = exp(-Ts / tau_v),
    };
}

void wiener_local_initial_state(const WienerLocalCoef *coef, const double acc0[3], WienerLocalState *state)
{
    double norm = sqrt(acc0[0] * acc0[0] + acc0[1] * acc0[1] + acc0[2] * acc0[2]), g = coef->g;
    *state = (WienerLocalState){
        .g = norm > 0.0 ? (Vec3){acc0[0] * (g / norm), acc0[1] * (g / norm), acc0[2] * (g / norm)}
                        : (Vec3){0.0, 0.0, g},
        .f = {acc0[0], acc0[1], acc0[2]},
        .q = {1.0, 0.0, 0.0, 0.0},
    };
}

/* 1/(4m + r)!, m = 0 ... 6, for r = 0 ... 3: the series of exp(z) grouped by the powers z^4m */
static const double INVERSE_FACTORIALS[4][7] = {
    {1.0, 0.041666666666666664, 2.48015873015873e-05, 2.08767569878681e-09, 4.779477332387385e-14,
     4.110317623312165e-19, 1.6117375710961184e-24},
    {1.0, 0.008333333333333333, 2.7557319223985893e-06, 1.6059043836821613e-10, 2.8114572543455206e-15,
     1.9572941063391263e-20, 6.446950284384474e-26},
    {0.5, 0.001388888888888889, 2.755731922398589e-07, 1.1470745597729725e-11, 1.5619206968586225e-16,
     8.896791392450574e-22, 2.4795962632247976e-27},
    {0.16666666666666666, 0.0001984126984126984, 2.505210838544172e-08, 7.647163731819816e-13,
     8.22063524662433e-18, 3.868170170630684e-23, 9.183689863795546e-29},
};

/* sum_m t^m / (4m + r)! for |t| <= 4 (the terms left out are below 1e-20 of the first); for
 * |t| <= 4e-4 the first three do as well */
static double grouped_series(int r, double t)
{
    const double *c = INVERSE_FACTORIALS[r];
    if (t >= -4e-4) return c[0] + t * (c[1] + t * c[2]);
    return c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * (c[5] + t * c[6])))));
}

void butterworth_zoh(double wt, double Ad[4], double Bd[2])
{
    /* M has eigenvalues (-1 +- i)/sqrt 2: exp(M t) = e^(-t/sqrt 2) (cos(t/sqrt 2) I + sqrt 2 sin(t/sqrt 2) (M + I/sqrt 2));
     * c = e^(-a) cos a and s = e^(-a) sin a, a = t/sqrt 2 */
    double a = wt * (1.0 / SQRT2), c, s;
    if (a <= 1.0) {
        /* e^(-a) (cos a + i sin a) = exp(z), z = a (i - 1), by its series: z^2 = -2i a^2, z^3 = 2 a^3 (1 + i) and
         * z^4 = -4 a^4 real, so exp(z) = P0 + z P1 + z^2 P2 + z^3 P3 with P_r = sum_m z^4m / (4m + r)! */
        double a2 = a * a, t = -4.0 * a2 * a2;
        double p1 = grouped_series(1, t), a3 = 2.0 * a2 * a * grouped_series(3, t);
        c = grouped_series(0, t) - a * p1 + a3;
        s = a * p1 - 2.0 * a2 * grouped_series(2, t) + a3;
    } else {
        double e = exp(-a);
        c = e * cos(a);
        s = e * sin(a);
    }
    Ad[0] = c + s;
    Ad[1] = SQRT2 * s;
    Ad[2] = -Ad[1];
    Ad[3] = c - s;
    /* M^-1 = [[-sqrt 2, -1], [1, 0]] applied to (Ad - I)[:, 1] */
    Bd[0] = -SQRT2 * Ad[1] - (Ad[3] - 1.0);
    Bd[1] = Ad[1];
}

/* The break frequency (eq. 25, rad/s) at the running densities W2 = <|w|^2> and V2 = <|v|^2>/3. */
static inline double break_frequency(const WienerLocalCoef *coef, double W2, double V2)
{
    double slosh = coef->inv_J * V2;
    return sqrt(coef->g * sqrt((coef->dn2 + coef->k_w * W2) / (coef->dv2_min > slosh ? coef->dv2_min : slosh)));
}

/* The first pass over a block of n samples: each sample's rotation dq and the running densities after
 * it (W2, V2). The accelerometer is band-passed into the slosh velocity v (f its low-pass), the rows
 * earth-fixed, turned into each sample's frame by the inverse of its rotation. */
static void densities(WienerLocalState *restrict state, const WienerLocalCoef *restrict coef, size_t n,
                      const double *restrict gyr, const double *restrict acc, Quat *restrict dq,
                      double *restrict W2s, double *restrict V2s)
{
    const double Ts = coef->Ts, a_avg = coef->a_avg, leak = coef->leak_v;
    Vec3 v = state->v, f = state->f;
    double W2 = state->w2, V2 = state->v2;
    for (size_t k = 0; k < n; k++) {
        const double *w = gyr + 3 * k, *y = acc + 3 * k;
        double w2, v2;
        dq[k] = rotvec_quat(w[0] * Ts, w[1] * Ts, w[2] * Ts);
        v = quat_rotate(quat_conjugate(dq[k]), v);
        f = quat_rotate(quat_conjugate(dq[k]), f);
        f.x += (1.0 - leak) * (y[0] - f.x);
        f.y += (1.0 - leak) * (y[1] - f.y);
        f.z += (1.0 - leak) * (y[2] - f.z);
        v.x = leak * v.x + Ts * (y[0] - f.x);
        v.y = leak * v.y + Ts * (y[1] - f.y);
        v.z = leak * v.z + Ts * (y[2] - f.z);
        v2 = v.x * v.x + v.y * v.y + v.z * v.z;
        w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        W2 += a_avg * (w2 - W2);
        V2 += a_avg * (v2 * (1.0 / 3.0) - V2);
        W2s[k] = W2;
        V2s[k] = V2;
    }
    state->v = v;
    state->f = f;
    state->w2 = W2;
    state->v2 = V2;
}

/* The second pass: the filter over n samples at each sample's break frequency omega (rad/s), the
 * estimates into gravity (n x 3); state's g, u, omega_g and t carried on. */
static void filter(WienerLocalState *restrict state, const WienerLocalCoef *restrict coef, size_t n,
                   const double *restrict acc, const Quat *restrict dq, const double *restrict omega,
                   double *restrict gravity)
{
    const double Ts = coef->Ts;
    Vec3 est = state->g, u = state->u;
    double last = state->omega_g, t = state->t;
    for (size_t k = 0; k < n; k++) {
        const double *y = acc + 3 * k;
        est = quat_rotate(quat_conjugate(dq[k]), est);
        u = quat_rotate(quat_conjugate(dq[k]), u);
        if (last > 0.0) { /* keep e = u/omega_g continuous across a change of omega_g */
            double ratio = omega[k] / last;
            u = (Vec3){u.x * ratio, u.y * ratio, u.z * ratio};
        }
        last = omega[k];
        t += Ts;
        if (t * omega[k] < SQRT2) {
            /* start-up, within the filter's time constant sqrt 2/omega_g: the mean of the
             * accelerometer so far in the gyro frame (no state velocity) */
            double count = t / Ts;
            est = (Vec3){est.x + (y[0] - est.x) / count, est.y + (y[1] - est.y) / count,
                         est.z + (y[2] - est.z) / count};
            u = (Vec3){0.0, 0.0, 0.0};
        } else {
            double Ad[4], Bd[2];
            Vec3 e = est;
            butterworth_zoh(omega[k] * Ts, Ad, Bd);
            est = (Vec3){Bd[0] * y[0] + Ad[0] * e.x + Ad[1] * u.x, Bd[0] * y[1] + Ad[0] * e.y + Ad[1] * u.y,
                         Bd[0] * y[2] + Ad[0] * e.z + Ad[1] * u.z};
            u = (Vec3){Bd[1] * y[0] + Ad[2] * e.x + Ad[3] * u.x, Bd[1] * y[1] + Ad[2] * e.y + Ad[3] * u.y,
                       Bd[1] * y[2] + Ad[2] * e.z + Ad[3] * u.z};
        }
        gravity[3 * k] = est.x, gravity[3 * k + 1] = est.y, gravity[3 * k + 2] = est.z;
    }
    state->g = est;
    state->u = u;
    state->omega_g = last;
    state->t = t;
}

/* The samples of a block (at most WIENER_LOCAL_BLOCK) in three passes, each with a short chain from
 * sample to sample: the local densities and the break frequencies, the filter, the levelled
 * orientation. */
static void block(WienerLocalState *restrict state, const WienerLocalCoef *restrict coef, size_t n,
                  const double *restrict gyr, const double *restrict acc, const double *restrict imposed,
                  double *restrict gravity, double *restrict quat, double *restrict used)
{
    Quat dq[WIENER_LOCAL_BLOCK];
    double omega[WIENER_LOCAL_BLOCK], W2s[WIENER_LOCAL_BLOCK], V2s[WIENER_LOCAL_BLOCK];
    densities(state, coef, n, gyr, acc, dq, W2s, V2s);
    for (size_t k = 0; k < n; k++) {
        omega[k] = imposed == NULL ? break_frequency(coef, W2s[k], V2s[k]) : imposed[k];
        if (used != NULL) used[k] = omega[k];
    }
    filter(state, coef, n, acc, dq, omega, gravity);
    /* the orientation: the gyro's, levelled onto each estimate */
    Quat q = state->q;
    for (size_t k = 0; k < n; k++) {
        const double *e = gravity + 3 * k;
        q = level_onto_gravity(q, dq[k], (Vec3){e[0], e[1], e[2]});
        quat_store(q, quat + 4 * k);
    }
    state->q = q;
}

void wiener_local_rows(WienerLocalState *state, const WienerLocalCoef *coef, size_t n, const double *gyr,
                       const double *acc, const double *imposed, double *gravity, double *quat, double *used)
{
    for (size_t k = 0; k < n; k += WIENER_LOCAL_BLOCK) {
        size_t m = n - k < WIENER_LOCAL_BLOCK ? n - k : WIENER_LOCAL_BLOCK;
        block(state, coef, m, gyr + 3 * k, acc + 3 * k, imposed != NULL ? imposed + k : NULL, gravity + 3 * k,
              quat + 4 * k, used != NULL ? used + k : NULL);
    }
}

void wiener_local_run(WienerLocalState *state, const WienerLocalCoef *coef, const double gyr[3], const double acc[3],
                      double gravity[3], double quat[4])
{
    block(state, coef, 1, gyr, acc, NULL, gravity, quat, NULL);
}

void wiener_local_gravities(WienerLocalState *states, const WienerLocalCoef *coefs, size_t count, size_t n,
                            const double *gyr, const double *acc, double *gravity, size_t stride)
{
    Quat dq[WIENER_LOCAL_BLOCK];
    double omega[WIENER_LOCAL_BLOCK], W2s[WIENER_LOCAL_BLOCK], V2s[WIENER_LOCAL_BLOCK];
    for (size_t k = 0; k < n; k += WIENER_LOCAL_BLOCK) {
        size_t m = n - k < WIENER_LOCAL_BLOCK ? n - k : WIENER_LOCAL_BLOCK;
        densities(&states[0], &coefs[0], m, gyr + 3 * k, acc + 3 * k, dq, W2s, V2s);
        for (size_t c = 0; c < count; c++) {
            if (c > 0) { /* the densities are the same for each */
                states[c].v = states[0].v, states[c].f = states[0].f;
                states[c].w2 = states[0].w2, states[c].v2 = states[0].v2;
            }
            for (size_t i = 0; i < m; i++) omega[i] = break_frequency(&coefs[c], W2s[i], V2s[i]);
            filter(&states[c], &coefs[c], m, acc + 3 * k, dq, omega, gravity + c * stride + 3 * k);
        }
    }
}
