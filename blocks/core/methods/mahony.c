/* mahony.c: Mahony's filter (see mahony.h). */
#include "mahony.h"

#include <math.h>

#include "messages.h"

int mahony_check_gains(double k_P, double k_I, double Ts, char *message, size_t size)
{
    /* "k_P\302\267Ts": k_P·Ts; "1/s\302\262": 1/s²; "\342\210\222": − (UTF-8) */
    if (k_P * Ts >= 2.0)
        return refuse(message, size,
                      "parameter k_P = %g 1/s is unstable at the sample time %g s: Mahony's step needs "
                      "k_P\302\267Ts < 2, k_P < %g 1/s at %g Hz",
                      k_P, Ts, 2.0 / Ts, 1.0 / Ts);
    if (k_I * Ts * Ts >= 4.0 - 2.0 * k_P * Ts)
        return refuse(message, size,
                      "parameter k_I = %g 1/s\302\262 is unstable with k_P = %g 1/s at the sample time %g s: "
                      "Mahony's step needs k_I\302\267Ts\302\262 < 4 \342\210\222 2\302\267k_P\302\267Ts, "
                      "k_I < %g 1/s\302\262 at %g Hz",
                      k_I, k_P, Ts, (4.0 - 2.0 * k_P * Ts) / (Ts * Ts), 1.0 / Ts);
    return 0;
}

int mahony_coefficients(const double params[AF_N_PARAMS], double Ts, MahonyCoef *coef, char *message, size_t size)
{
    if (mahony_check_gains(params[AF_P_k_P], params[AF_P_k_I], Ts, message, size)) return -1;
    *coef = (MahonyCoef){params[AF_P_k_P], params[AF_P_k_I], Ts, params[AF_P_g]};
    return 0;
}

void mahony_initial_state(const MahonyCoef *coef, const double acc0[3], MahonyState *state)
{
    (void)coef;
    *state = (MahonyState){level_on(acc0), {0.0, 0.0, 0.0}};
}

Quat level_on(const double acc0[3])
{
    double norm = sqrt(acc0[0] * acc0[0] + acc0[1] * acc0[1] + acc0[2] * acc0[2]);
    if (norm == 0.0) return (Quat){1.0, 0.0, 0.0, 0.0}; /* no reading to level on (free fall): level */
    double u0 = acc0[0] / norm, u1 = acc0[1] / norm, u2 = acc0[2] / norm;
    double w = 1.0 + u2, qn;
    if (w < 1e-12) return (Quat){0.0, 1.0, 0.0, 0.0};
    qn = sqrt(w * w + u1 * u1 + u0 * u0);
    return (Quat){w / qn, u1 / qn, -u0 / qn, 0.0 / qn};
}

Vec3 mahony_step(MahonyState *state, double k_P, double k_I, double Ts, const double gyr[3], const double acc[3])
{
    Quat q = state->q;
    Vec3 v_hat = up_in_sensor(q);
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double norm = sqrt(a0 * a0 + a1 * a1 + a2 * a2);
    double e0 = 0.0, e1 = 0.0, e2 = 0.0;
    if (norm > 0.0) {
        double v0 = a0 / norm, v1 = a1 / norm, v2 = a2 / norm;
        e0 = v1 * v_hat.z - v2 * v_hat.y;
        e1 = v2 * v_hat.x - v0 * v_hat.z;
        e2 = v0 * v_hat.y - v1 * v_hat.x;
    }
    state->b.x -= k_I * e0 * Ts;
    state->b.y -= k_I * e1 * Ts;
    state->b.z -= k_I * e2 * Ts;
    double w[3] = {gyr[0] - state->b.x + k_P * e0, gyr[1] - state->b.y + k_P * e1, gyr[2] - state->b.z + k_P * e2};
    state->q = quat_turned(q, w, Ts);
    return up_in_sensor(state->q);
}

void mahony_run(MahonyState *state, const MahonyCoef *coef, const double gyr[3], const double acc[3],
                double gravity[3], double quat[4])
{
    Vec3 up = mahony_step(state, coef->k_P, coef->k_I, coef->Ts, gyr, acc);
    write_sample(gravity, quat, coef->g, up, state->q);
}
