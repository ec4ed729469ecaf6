/* lever_arm.c: the lever-arm fit's normal equations (see lever_arm.h). */
#include "lever_arm.h"

#include <string.h>

#include "quaternion.h"

/* A window's sums: of X^T.X, X^T.y, |y|^2 over its samples and of X and y, into the totals freed of the
 * window's means: sum (x - mean)(x - mean)^T = sum x x^T - (sum x)(sum x)^T / count. */
typedef struct {
    double xx[9], xy[3], yy, x[9], y[3];
    size_t count;
} Sums;

static void add_window(Sums *w, double normal[9], double moment[3], double *total)
{
    if (w->count == 0)
        return;
    double inv = 1.0 / (double)w->count;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double sx = 0.0;
            for (int k = 0; k < 3; k++)
                sx += w->x[3 * k + i] * w->x[3 * k + j];
            normal[3 * i + j] += w->xx[3 * i + j] - sx * inv;
        }
        double sy = 0.0;
        for (int k = 0; k < 3; k++)
            sy += w->x[3 * k + i] * w->y[k];
        moment[i] += w->xy[i] - sy * inv;
    }
    *total += w->yy - (w->y[0] * w->y[0] + w->y[1] * w->y[1] + w->y[2] * w->y[2]) * inv;
    memset(w, 0, sizeof *w);
}

/* the rotation's terms at sample k of n: A (3 x 3, row-major) = [alpha]x + w w^T - |w|^2 I, A.r = alpha x r +
 * w x (w x r); the gyro's mean rates over the span samples before t_k (gyr[k - span + 1 .. k]) and the span
 * after (gyr[k + 1 .. k + span]), rows beyond the recording its first or last: w their mean, alpha their
 * difference over span Ts */
static void rotation_terms(size_t n, size_t k, const double *gyr, double Ts, size_t span, double A[9])
{
    double before[3] = {0.0, 0.0, 0.0}, after[3] = {0.0, 0.0, 0.0};
    for (size_t j = 0; j < span; j++) {
        const double *b = gyr + 3 * (k >= j ? k - j : 0), *a = gyr + 3 * (k + 1 + j < n ? k + 1 + j : n - 1);
        for (int i = 0; i < 3; i++)
            before[i] += b[i], after[i] += a[i];
    }
    double rate[3], turn[3];
    for (int i = 0; i < 3; i++) {
        rate[i] = 0.5 * (before[i] + after[i]) / (double)span;
        turn[i] = (after[i] - before[i]) / ((double)span * (double)span * Ts);
    }
    lever_arm_terms(rate, turn, A);
}

void lever_arm_removed(size_t n, const double *gyr, const double *acc, double Ts, size_t span, const double r[3],
                       double *out)
{
    for (size_t k = 0; k < n; k++) {
        double A[9];
        rotation_terms(n, k, gyr, Ts, span, A);
        for (int i = 0; i < 3; i++)
            out[3 * k + i] = acc[3 * k + i] - (A[3 * i] * r[0] + A[3 * i + 1] * r[1] + A[3 * i + 2] * r[2]);
    }
}

void lever_arm_sums(size_t n, const double *gyr, const double *acc, double Ts, size_t span, size_t window,
                    double normal[9], double moment[3], double *total)
{
    memset(normal, 0, 9 * sizeof *normal);
    memset(moment, 0, 3 * sizeof *moment);
    *total = 0.0;
    Sums w;
    memset(&w, 0, sizeof w);
    Quat q = {1.0, 0.0, 0.0, 0.0};
    for (size_t k = 0; k < n; k++) {
        const double *g = gyr + 3 * k, *a = acc + 3 * k;
        q = quat_turned(q, g, Ts);
        double R[9], A[9], X[9], y[3];
        quat_matrix(q, R);
        rotation_terms(n, k, gyr, Ts, span, A);
        lever_arm_turned(R, A, X);
        for (int i = 0; i < 3; i++)
            y[i] = R[3 * i] * a[0] + R[3 * i + 1] * a[1] + R[3 * i + 2] * a[2];
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++)
                w.xx[3 * i + j] += X[i] * X[j] + X[3 + i] * X[3 + j] + X[6 + i] * X[6 + j];
            w.xy[i] += X[i] * y[0] + X[3 + i] * y[1] + X[6 + i] * y[2];
        }
        for (int i = 0; i < 9; i++)
            w.x[i] += X[i];
        for (int i = 0; i < 3; i++) {
            w.y[i] += y[i];
            w.yy += y[i] * y[i];
        }
        if (++w.count == window)
            add_window(&w, normal, moment, total);
    }
    add_window(&w, normal, moment, total);
}
