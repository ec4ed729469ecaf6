/* earth_filters.h: Rizun's (2008) earth-frame attitude filters as continuous-time SISO state
 * spaces, the realisation python-control gives their transfer functions.
 * The FMUs, which carry no Python, design their filters here; the Python package designs the
 * same with python-control (blocks/filters/earth_filters.py, same names and messages) and hands
 * down their zero-order holds. Frequencies in rad/s, noise densities one-sided
 * (docs/conventions.md). Functions that refuse return 0, or -1 with a message. */
#ifndef AF_EARTH_FILTERS_H
#define AF_EARTH_FILTERS_H

#include <stddef.h>

#define STANDARD_GRAVITY 9.81 /* m/s^2, the value the project uses for |g| */
#define MAX_ORDER 5           /* the largest earth-filter order: the tseng method's */
#define SQRT2 1.4142135623730951

/* dx/dt = A x + B u, y = C x + D u: one axis, n states, A row-major n x n. */
typedef struct {
    int n;
    double A[MAX_ORDER * MAX_ORDER];
    double B[MAX_ORDER];
    double C[MAX_ORDER];
    double D;
} EarthFilter;

/* The state space of num(s)/den(s) (coefficients from the highest power, n_num <= n_den <=
 * MAX_ORDER + 1) as control.ss realises a transfer function without slycot
 * (scipy.signal.tf2ss: controller canonical form, after scipy.signal.normalize). */
void state_space(const double *num, int n_num, const double *den, int n_den, EarthFilter *out);

/* Eq. 25: the Butterworth break frequency sqrt(g delta_n / delta_v), rad/s, into *out;
 * delta_n rad/s/sqrt(Hz), delta_v m/s/sqrt(Hz), g m/s^2, each finite and positive. */
int omega_g(double delta_n, double delta_v, double g, double *out, char *message, size_t size);

/* Eq. 34: omega_g^2 / (s^2 + sqrt(2) omega_g s + omega_g^2). */
int butterworth(double omega_g, EarthFilter *out, char *message, size_t size);

/* Eq. 27: asin(omega_g^2 / (2 omega_c^2)), rad; refused unless omega_c > omega_g / sqrt(2). */
int delta_phi(double omega_g, double omega_c, double *out, char *message, size_t size);

/* Eq. 33: omega_g^2 (1 + s/omega_c) / (s^2 + sqrt(2) omega_g (cos(dphi/2) + sin(dphi/2)) s + omega_g^2). */
int wiener_band_limited(double omega_g, double omega_c, EarthFilter *out, char *message, size_t size);

/* Section 4.2: omega_f / (s + omega_f). */
int first_order(double omega_f, EarthFilter *out, char *message, size_t size);

/* The first-order cut-off of least mean-square error, (omega_g^4 / (2 omega_c))^(1/3), rad/s. */
int best_first_order_cutoff(double omega_g, double omega_c, double *out, char *message, size_t size);

#endif
