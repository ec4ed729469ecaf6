/* mahony.c: Python twin blocks/methods/mahony.py; the same operations in the same order. */
#include "mahony.h"

#include <math.h>

#include "messages.h"

int mahony_check_gains(double k_P, double k_I, double Ts, char *message, size_t size)
{
    /* "k_P\302\267Ts": k_P·Ts; "1/s\302\262": 1/s²; "\342\210\222": − (UTF-8, as Python's message) */
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

int mahony_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[MAHONY_COEF_SIZE], char *message,
                        size_t size)
{
    if (mahony_check_gains(params[AF_P_k_P], params[AF_P_k_I], Ts, message, size)) return -1;
    coef[0] = params[AF_P_k_P];
    coef[1] = params[AF_P_k_I];
    coef[2] = Ts;
    coef[3] = params[AF_P_g];
    return 0;
}

void mahony_initial_state(const double coef[MAHONY_COEF_SIZE], const double acc0[3], double state[MAHONY_STATE_SIZE])
{
    (void)coef;
    level_on(acc0, state);
    state[4] = state[5] = state[6] = 0.0;
}

void level_on(const double acc0[3], double q[4])
{
    double norm = sqrt(acc0[0] * acc0[0] + acc0[1] * acc0[1] + acc0[2] * acc0[2]);
    double u0 = acc0[0] / norm, u1 = acc0[1] / norm, u2 = acc0[2] / norm;
    double w = 1.0 + u2, qn;
    if (w < 1e-12) {
        q[0] = 0.0;
        q[1] = 1.0;
        q[2] = q[3] = 0.0;
        return;
    }
    qn = sqrt(w * w + u1 * u1 + u0 * u0);
    q[0] = w / qn;
    q[1] = u1 / qn;
    q[2] = -u0 / qn;
    q[3] = 0.0 / qn;
}

Vec3 mahony_step(double state[MAHONY_STATE_SIZE], double k_P, double k_I, double Ts, const double gyr[3],
                 const double acc[3])
{
    Quat q = quat_load(state);
    Vec3 v_hat = up_in_sensor(q);
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double norm = sqrt(a0 * a0 + a1 * a1 + a2 * a2);
    double e0 = 0.0, e1 = 0.0, e2 = 0.0, w0, w1, w2;
    if (norm > 0.0) {
        double v0 = a0 / norm, v1 = a1 / norm, v2 = a2 / norm;
        e0 = v1 * v_hat.z - v2 * v_hat.y;
        e1 = v2 * v_hat.x - v0 * v_hat.z;
        e2 = v0 * v_hat.y - v1 * v_hat.x;
    }
    state[4] -= k_I * e0 * Ts;
    state[5] -= k_I * e1 * Ts;
    state[6] -= k_I * e2 * Ts;
    w0 = gyr[0] - state[4] + k_P * e0;
    w1 = gyr[1] - state[5] + k_P * e1;
    w2 = gyr[2] - state[6] + k_P * e2;
    q = quat_normalized(quat_multiply(q, rotvec_quat(w0 * Ts, w1 * Ts, w2 * Ts)));
    quat_store(q, state);
    return up_in_sensor(q);
}

void mahony_run(double state[MAHONY_STATE_SIZE], const double coef[MAHONY_COEF_SIZE], const double gyr[3],
                const double acc[3], double gravity[3], double quat[4])
{
    Vec3 up = mahony_step(state, coef[0], coef[1], coef[2], gyr, acc);
    write_sample(gravity, quat, coef[3], up, state);
}
