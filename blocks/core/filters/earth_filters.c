/* earth_filters.c: the earth-frame filters' designs (see earth_filters.h), realised as
 * control.ss does (state_space). */
#include "earth_filters.h"

#include <math.h>

#include "messages.h"

void state_space(const double *num, int n_num, const double *den, int n_den, EarthFilter *out)
{
    double b[MAX_ORDER + 1] = {0.0}, a[MAX_ORDER + 1] = {0.0};
    int lead = 0, i, j, n;
    while (lead < n_den - 1 && den[lead] == 0.0) lead++; /* scipy.signal.normalize */
    n_den -= lead;
    den += lead;
    for (i = 0; i < n_den; i++) a[i] = den[i] / den[0];
    while (n_num > 1 && fabs(num[0] / den[0]) <= 1e-14) { /* normalize drops such leading numerator terms */
        num++;
        n_num--;
    }
    for (i = 0; i < n_den; i++) /* the numerator padded to the denominator's length */
        b[i] = i < n_den - n_num ? 0.0 : num[i - (n_den - n_num)] / den[0];
    n = n_den - 1;
    out->n = n;
    out->D = b[0];
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) out->A[i * n + j] = i == 0 ? -a[j + 1] : (i == j + 1 ? 1.0 : 0.0);
        out->B[i] = i == 0 ? 1.0 : 0.0;
        out->C[i] = b[i + 1] - b[0] * a[i + 1];
    }
}

/* _require_positive */
static int require_positive(const char *name, double value, char *message, size_t size)
{
    char text[FLOAT_REPR_SIZE];
    if (isfinite(value) && value > 0) return 0;
    return refuse(message, size, "%s must be a finite positive number, got %s", name, float_repr(value, text));
}

int omega_g(double delta_n, double delta_v, double g, double *out, char *message, size_t size)
{
    if (require_positive("delta_n", delta_n, message, size) || require_positive("delta_v", delta_v, message, size) ||
        require_positive("g", g, message, size))
        return -1;
    *out = sqrt(g * delta_n / delta_v);
    return 0;
}

int butterworth(double omega_g, EarthFilter *out, char *message, size_t size)
{
    if (require_positive("omega_g", omega_g, message, size)) return -1;
    {
        double num[1] = {pow(omega_g, 2.0)};
        double den[3] = {1.0, SQRT2 * omega_g, pow(omega_g, 2.0)};
        state_space(num, 1, den, 3, out);
    }
    return 0;
}

int delta_phi(double omega_g, double omega_c, double *out, char *message, size_t size)
{
    if (require_positive("omega_g", omega_g, message, size) || require_positive("omega_c", omega_c, message, size))
        return -1;
    if (omega_c <= omega_g / SQRT2)
        return refuse(message, size,
                      "omega_c = %g rad/s must exceed omega_g/sqrt(2) = %g rad/s (the assumption behind eq. 26)",
                      omega_c, omega_g / SQRT2);
    *out = asin(pow(omega_g, 2.0) / (2.0 * pow(omega_c, 2.0)));
    return 0;
}

int wiener_band_limited(double omega_g, double omega_c, EarthFilter *out, char *message, size_t size)
{
    double dphi = 0.0, damping;
    if (delta_phi(omega_g, omega_c, &dphi, message, size)) return -1;
    damping = SQRT2 * omega_g * (cos(dphi / 2) + sin(dphi / 2));
    {
        double num[2] = {pow(omega_g, 2.0) / omega_c, pow(omega_g, 2.0)};
        double den[3] = {1.0, damping, pow(omega_g, 2.0)};
        state_space(num, 2, den, 3, out);
    }
    return 0;
}

int first_order(double omega_f, EarthFilter *out, char *message, size_t size)
{
    if (require_positive("omega_f", omega_f, message, size)) return -1;
    {
        double num[1] = {omega_f}, den[2] = {1.0, omega_f};
        state_space(num, 1, den, 2, out);
    }
    return 0;
}

int best_first_order_cutoff(double omega_g, double omega_c, double *out, char *message, size_t size)
{
    if (require_positive("omega_g", omega_g, message, size) || require_positive("omega_c", omega_c, message, size))
        return -1;
    *out = pow(pow(omega_g, 4.0) / (2.0 * omega_c), 1.0 / 3.0);
    return 0;
}
