/* sensor_frame.c: the sensor-frame transformation (see sensor_frame.h). The core's own
 * zero-order hold is control.c2d's: the exponential of the filter's [[A, B], [0, 0]] Ts
 * (filters/matrix.c). */
#include "sensor_frame.h"

#include <math.h>

#include "filters/matrix.h"
#include "messages.h"

int discrete_filter(const EarthFilter *f, double Ts, DiscreteFilter *out, char *message, size_t size)
{
    double work[ZERO_ORDER_HOLD_WORK(MAX_ORDER, 1)];
    char text[FLOAT_REPR_SIZE];
    if (!(isfinite(Ts) && Ts > 0))
        return refuse(message, size, "sample time Ts must be a finite positive number of seconds, got %s",
                      float_repr(Ts, text));
    zero_order_hold(f->n, 1, f->A, f->B, Ts, out->Ad, out->Bd, work);
    out->n = f->n;
    for (int i = 0; i < f->n; i++) out->C[i] = f->C[i];
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

/* The discrete LTI filter per axis on the rows Xr: X = Ad Xr + Bd acc^T, g_out = C X + D acc (n states). */
static void filter_rows(Vec3 *X, const Vec3 *Xr, const double acc[3], int n, const double *Ad, const double *Bd,
                        const double *C, double D, double g_out[3])
{
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double g0 = D * a0, g1 = D * a1, g2 = D * a2;
    for (int j = 0; j < n; j++) {
        double s0 = Bd[j] * a0, s1 = Bd[j] * a1, s2 = Bd[j] * a2;
        for (int m = 0; m < n; m++) {
            s0 += Ad[j * n + m] * Xr[m].x;
            s1 += Ad[j * n + m] * Xr[m].y;
            s2 += Ad[j * n + m] * Xr[m].z;
        }
        X[j] = (Vec3){s0, s1, s2};
        g0 += C[j] * s0;
        g1 += C[j] * s1;
        g2 += C[j] * s2;
    }
    g_out[0] = g0;
    g_out[1] = g1;
    g_out[2] = g2;
}

void sensor_frame_step(Vec3 *X, Quat *q, const double gyr[3], const double acc[3], int n, const double *Ad,
                       const double *Bd, const double *C, double D, double Ts, double g_out[3])
{
    Vec3 Xr[MAX_ORDER];
    Quat dq = rotvec_quat(gyr[0] * Ts, gyr[1] * Ts, gyr[2] * Ts);
    /* the rows, earth-fixed, turned into this sample's sensor frame: by the inverse rotation */
    for (int j = 0; j < n; j++) Xr[j] = quat_rotate(quat_conjugate(dq), X[j]);
    filter_rows(X, Xr, acc, n, Ad, Bd, C, D, g_out);
    *q = level_onto_gravity(*q, dq, (Vec3){g_out[0], g_out[1], g_out[2]});
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
    quat_store((Quat){1.0, 0.0, 0.0, 0.0}, state + 3 * d->n);
}
