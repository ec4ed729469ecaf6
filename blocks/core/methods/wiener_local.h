/* wiener_local.h: Rizun's Wiener filter with its noise densities estimated locally (the
 * default `wiener`; blocks/methods/wiener_local.py tells the model): eq. 34 in the sensor
 * frame, omega_g re-derived every sample from the gyro's and the slosh's densities over the
 * last tau_noise seconds. */
#ifndef AF_WIENER_LOCAL_H
#define AF_WIENER_LOCAL_H

#include <stddef.h>

#include "af_params.h"
#include "quaternion.h"

/* The state: rows of 3 that turn with the gyro, the orientation, the running densities. */
typedef struct {
    Vec3 g;         /* the gravity estimate, m/s^2, sensor coordinates */
    Vec3 u;         /* omega_g e, e the filter's velocity residual (m/s), so m/s^2 */
    Vec3 v;         /* band-passed velocity of the noise estimate, m/s */
    Vec3 f;         /* low-passed accelerometer, m/s^2 */
    Quat q;         /* orientation, sensor -> earth */
    double w2;      /* <|w|^2>, rad^2/s^2 */
    double v2;      /* <|v|^2>/3, m^2/s^2 */
    double omega_g; /* the last break frequency, rad/s */
    double t;       /* time since the start, s */
} WienerLocalState;

#define WIENER_LOCAL_STATE_SIZE 20 /* doubles in a WienerLocalState */
typedef char wiener_local_state_size[sizeof(WienerLocalState) == WIENER_LOCAL_STATE_SIZE * sizeof(double) ? 1 : -1];

/* The coefficients at a sample time: dn_eff^2 = dn2 + k_w <|w|^2>, dv^2 = <|v|^2>/(3 J). */
typedef struct {
    double Ts;      /* s */
    double g;       /* m/s^2 */
    double dn2;     /* delta_n^2 */
    double k_w;     /* 4 scale_error^2/omega_m */
    double inv_J;   /* 1/J (band_pass_variance) */
    double dv2_min; /* delta_v_min^2 */
    double a_avg;   /* 1 - exp(-Ts/tau_noise) */
    double leak_v;  /* exp(-Ts/tau_v) */
} WienerLocalCoef;

/* J, the variance per unit density that the band-pass of time constant tau_v (s) leaves of
 * eq. 14's velocity band-limited at omega_m (rad/s): (1/2 pi) int (w tau_v)^4 / (1 + w^2
 * tau_v^2)^2 / (1 + w^2/omega_m^2) dw, in closed form c^2 (2c + 1) / (8 tau_v (1 + c)^2),
 * c = omega_m tau_v. */
double band_pass_variance(double omega_m, double tau_v);

/* coefficients(params, Ts): params the method's resolved values (AF_P_<name>), Ts s. */
void wiener_local_coefficients(const double params[AF_N_PARAMS], double Ts, WienerLocalCoef *coef);

/* At rest on acc0 (m/s^2): g along acc0 with the magnitude coef->g, q the identity. */
void wiener_local_initial_state(const WienerLocalCoef *coef, const double acc0[3], WienerLocalState *state);

/* Ad = exp(M wt), Bd = M^-1 (Ad - I) [0, 1] of the realisation M = [[0, 1], [-1, -sqrt 2]] for
 * wt = omega_g Ts (rad), in closed form; Ad 2 x 2 row-major. */
void butterworth_zoh(double wt, double Ad[4], double Bd[2]);

#define WIENER_LOCAL_BLOCK 64 /* samples computed pass by pass (wiener_local_rows) */

/* n samples: gyr (n x 3, rad/s, each the mean over its sample), acc (n x 3, m/s^2); the gravity
 * estimates (n x 3, m/s^2) and q (n x 4) written, state in place. imposed: the n break
 * frequencies to use (rad/s; the offline smoother's passes; the densities are updated all the
 * same), NULL: the local densities'; used: where not NULL, the n break frequencies used. The
 * samples are computed in blocks of WIENER_LOCAL_BLOCK, pass by pass (the densities, the filter,
 * the levelled orientation), each sample's operations those of a step of its own. */
void wiener_local_rows(WienerLocalState *state, const WienerLocalCoef *coef, size_t n, const double *gyr,
                       const double *acc, const double *imposed, double *gravity, double *quat, double *used);

/* One sample at the local densities' break frequency. */
void wiener_local_run(WienerLocalState *state, const WienerLocalCoef *coef, const double gyr[3], const double acc[3],
                      double gravity[3], double quat[4]);

/* count filters over the same n samples, filter c as wiener_local_rows runs it from states[c] with
 * coefs[c], its gravity estimates (n x 3) at gravity + c stride, the densities computed once: the
 * coefficients share Ts, a_avg and leak_v, and the states their densities (v, f, w2, v2); the
 * orientation q is neither computed nor carried on (the scale_error choice's candidates,
 * stages/scale_error.h). count >= 1. */
void wiener_local_gravities(WienerLocalState *states, const WienerLocalCoef *coefs, size_t count, size_t n,
                            const double *gyr, const double *acc, double *gravity, size_t stride);

#endif
