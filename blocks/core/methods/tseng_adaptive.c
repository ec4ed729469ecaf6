/* tseng_adaptive.c: Python twin blocks/methods/tseng_adaptive.py; the same operations in the
 * same order, through the same steps (sensor_frame_step, mahony_step). */
#include "tseng_adaptive.h"

#include <math.h>

#include "filters/sensor_frame.h"
#include "methods/mahony.h"

int tseng_adaptive_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[TSENG_ADAPTIVE_COEF_SIZE],
                                char *message, size_t size)
{
    static const double unit_input[3] = {1.0, 0.0, 0.0};
    EarthFilter f;
    DiscreteFilter disc;
    double X[3 * MAX_ORDER];
    int n, j;
    if (mahony_check_gains(params[AF_P_k_P], params[AF_P_k_I], Ts, message, size)) return -1; /* its Mahony mode's */
    tseng_earth_filter(&f);
    if (discrete_filter(&f, Ts, &disc, message, size)) return -1;
    n = disc.n;
    rest_state(&disc, unit_input, X);
    coef[0] = n;
    coef[1] = Ts;
    coef[2] = params[AF_P_tol];
    coef[3] = params[AF_P_g];
    coef[4] = params[AF_P_k_P];
    coef[5] = params[AF_P_k_I];
    coef[6] = disc.D;
    for (j = 0; j < n * n; j++) coef[7 + j] = disc.Ad[j];
    for (j = 0; j < n; j++) {
        coef[7 + n * n + j] = disc.Bd[j];
        coef[7 + n * n + n + j] = disc.C[j];
        coef[7 + n * n + 2 * n + j] = X[3 * j];
    }
    return 0;
}

void tseng_adaptive_initial_state(const double coef[TSENG_ADAPTIVE_COEF_SIZE], const double acc0[3],
                                  double state[TSENG_ADAPTIVE_STATE_SIZE])
{
    int n = (int)coef[0], j, i;
    const double *x_rest = coef + 7 + n * n + 2 * n;
    for (j = 0; j < n; j++)
        for (i = 0; i < 3; i++) state[3 * j + i] = x_rest[j] * acc0[i];
    state[3 * n] = 1.0;
    for (i = 1; i < 7; i++) state[3 * n + i] = 0.0;
}

void tseng_adaptive_run(double state[TSENG_ADAPTIVE_STATE_SIZE], const double coef[TSENG_ADAPTIVE_COEF_SIZE],
                        const double gyr[3], const double acc[3], double gravity[3], double quat[4])
{
    int n = (int)coef[0], j, i;
    double Ts = coef[1], tol = coef[2], g = coef[3], k_P = coef[4], k_I = coef[5], D = coef[6];
    const double *Ad = coef + 7, *Bd = coef + 7 + n * n, *C = coef + 7 + n * n + n, *x_rest = coef + 7 + n * n + 2 * n;
    double *X = state, *q = state + 3 * n;
    double *mahony_state = state + 3 * n; /* q then b, as blocks.methods.mahony keeps them */
    double norm = sqrt(acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]);
    if (fabs(norm - g) <= tol) {
        sensor_frame_step(X, q, gyr, acc, n, Ad, Bd, C, D, Ts, gravity);
    } else {
        Vec3 up = mahony_step(mahony_state, k_P, k_I, Ts, gyr, acc);
        double u[3] = {up.x, up.y, up.z};
        for (j = 0; j < n; j++)
            for (i = 0; i < 3; i++) X[3 * j + i] = x_rest[j] * g * u[i];
        gravity[0] = g * up.x;
        gravity[1] = g * up.y;
        gravity[2] = g * up.z;
    }
    for (i = 0; i < 4; i++) quat[i] = q[i];
}
