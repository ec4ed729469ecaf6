/* tseng.c: the `tseng` method's earth-frame filter from the paper's transfer functions. */
#include "tseng.h"

#include <math.h>

/* Tseng et al.'s polynomials, highest power of s first: G_A's numerator (eq. 6), G_LA's
 * denominator (eq. 9), G_H = s^2 / D_H (eq. 11), G_G = (s + 0.0185) / s (eq. 8). */
static const double N_A[3] = {0.1 * 0.05, 0.1 + 0.05, 1.0};
static const double D_LA[4] = {0.063, 0.475, 1.1937, 1.0};
static const double D_H[3] = {1.0, 0.6, 0.09};
static const double S_G[3] = {1.0, 0.0185, 0.0}; /* s (s + 0.0185) */

/* out (na + nb - 1 coefficients) = a * b */
static void polymul(const double *a, int na, const double *b, int nb, double *out)
{
    for (int i = 0; i < na + nb - 1; i++) out[i] = 0.0;
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++) out[i + j] += a[i] * b[j];
}

void tseng_earth_filter(EarthFilter *out)
{
    /* C G_LA = G_LA / (G_LA G_A + G_H G_G); the factor s common to both terms cancels:
     * D_H / (N_A D_H + s (s + 0.0185) D_LA), of order 5 */
    double first[5], second[6], den[TSENG_ORDER + 1];
    polymul(N_A, 3, D_H, 3, first);
    polymul(S_G, 3, D_LA, 4, second);
    for (int i = 0; i <= TSENG_ORDER; i++) den[i] = second[i] + (i >= 1 ? first[i - 1] : 0.0);
    state_space(D_H, 3, den, TSENG_ORDER + 1, out);
}

void euler_rates(size_t n, const double *gyr, double Ts, double roll0, double pitch0, double *roll, double *pitch)
{
    double phi = roll0, theta = pitch0;
    for (size_t k = 0; k < n; k++) {
        double p = gyr[3 * k], q = gyr[3 * k + 1], r = gyr[3 * k + 2];
        double next_phi = phi + Ts * (p + tan(theta) * (q * sin(phi) + r * cos(phi)));
        theta = theta + Ts * (q * cos(phi) - r * sin(phi));
        phi = next_phi;
        roll[k] = phi;
        pitch[k] = theta;
    }
}
