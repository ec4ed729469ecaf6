/* sensor_frame.c: Python twin blocks/filters/sensor_frame.py; the same operations in the
 * same order. The zero-order hold is control.c2d's: the exponential of the filter's
 * [[A, B], [0, 0]] Ts (filters/matrix.c). */
#include "sensor_frame.h"

#include <math.h>

#include "filters/matrix.h"
#include "messages.h"

int discrete_filter(const EarthFilter *f, double Ts, DiscreteFilter *out, char *message, size_t size)
{
    double M[MATRIX_MAX * MATRIX_MAX] = {0.0}, E[MATRIX_MAX * MATRIX_MAX];
    char text[FLOAT_REPR_SIZE];
    int n = f->n, m = f->n + 1, i, j;
    if (!(isfinite(Ts) && Ts > 0))
        return refuse(message, size, "sample time Ts must be a finite positive number of seconds, got %s",
                      float_repr(Ts, text));
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) M[i * m + j] = Ts * f->A[i * n + j];
        M[i * m + n] = Ts * f->B[i];
    }
    expm(m, M, E);
    out->n = n;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) out->Ad[i * n + j] = E[i * m + j];
        out->Bd[i] = E[i * m + n];
        out->C[i] = f->C[i];
    }
    out->D = f->D;
    out->Ts = Ts;
    return 0;
}

void rest_state(const DiscreteFilter *d, const double acc0[3], double *X)
{
    double I_Ad[MAX_ORDER * MAX_ORDER], unit[MAX_ORDER];
    int n = d->n, i, j;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) I_Ad[i * n + j] = (i == j ? 1.0 : 0.0) - d->Ad[i * n + j];
        unit[i] = d->Bd[i];
    }
    solve(n, I_Ad, 1, unit);
    for (j = 0; j < n; j++)
        for (i = 0; i < 3; i++) X[j * 3 + i] = unit[j] * acc0[i];
}

Quat turn_rows(const double *X, double *Xr, int n, const double gyr[3], double Ts)
{
    Quat dq = rotvec_quat(gyr[0] * Ts, gyr[1] * Ts, gyr[2] * Ts);
    /* a vector fixed in the earth frame turns by the inverse rotation in sensor coordinates */
    Quat dq_inv = quat_conjugate(dq);
    int j;
    for (j = 0; j < n; j++) {
        Vec3 v = quat_rotate(dq_inv, (Vec3){X[j * 3], X[j * 3 + 1], X[j * 3 + 2]});
        Xr[j * 3] = v.x;
        Xr[j * 3 + 1] = v.y;
        Xr[j * 3 + 2] = v.z;
    }
    return dq;
}

void filter_rows(double *X, const double *Xr, const double acc[3], int n, const double *Ad, const double *Bd,
                 const double *C, double D, double g_out[3])
{
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double g0 = D * a0, g1 = D * a1, g2 = D * a2;
    int j, m;
    for (j = 0; j < n; j++) {
        double s0 = Bd[j] * a0, s1 = Bd[j] * a1, s2 = Bd[j] * a2;
        for (m = 0; m < n; m++) {
            s0 += Ad[j * n + m] * Xr[m * 3];
            s1 += Ad[j * n + m] * Xr[m * 3 + 1];
            s2 += Ad[j * n + m] * Xr[m * 3 + 2];
        }
        X[j * 3] = s0;
        X[j * 3 + 1] = s1;
        X[j * 3 + 2] = s2;
        g0 += C[j] * s0;
        g1 += C[j] * s1;
        g2 += C[j] * s2;
    }
    g_out[0] = g0;
    g_out[1] = g1;
    g_out[2] = g2;
}

void level_onto_gravity(double q[4], Quat dq, const double g[3])
{
    double g0 = g[0], g1 = g[1], g2 = g[2];
    Quat qt = quat_multiply(quat_load(q), dq);
    double norm = sqrt(g0 * g0 + g1 * g1 + g2 * g2);
    if (norm > 0.0) qt = quat_multiply(level_quat(quat_rotate(qt, (Vec3){g0, g1, g2}), norm), qt);
    quat_store(quat_normalized(qt), q);
}

void sensor_frame_step(double *X, double q[4], const double gyr[3], const double acc[3], int n, const double *Ad,
                       const double *Bd, const double *C, double D, double Ts, double g_out[3])
{
    double Xr[MAX_ORDER * 3];
    Quat dq = turn_rows(X, Xr, n, gyr, Ts);
    filter_rows(X, Xr, acc, n, Ad, Bd, C, D, g_out);
    level_onto_gravity(q, dq, g_out);
}

void start_gravity(const double gyr0[3], const double acc0[3], double Ts, double out[3])
{
    Quat dq = rotvec_quat(gyr0[0] * Ts, gyr0[1] * Ts, gyr0[2] * Ts);
    Vec3 v = quat_rotate(dq, (Vec3){acc0[0], acc0[1], acc0[2]});
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
}

void sensor_frame_initial_state(const DiscreteFilter *d, const double acc0[3], double *state)
{
    rest_state(d, acc0, state);
    state[3 * d->n] = 1.0;
    state[3 * d->n + 1] = 0.0;
    state[3 * d->n + 2] = 0.0;
    state[3 * d->n + 3] = 0.0;
}
