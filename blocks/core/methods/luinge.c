/* luinge.c: Python twin blocks/methods/luinge.py; the same operations in the same order. */
#include "luinge.h"

#include <math.h>

#include "methods/mahony.h"

void luinge_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[LUINGE_COEF_SIZE])
{
    coef[0] = pow(params[AF_P_delta_n], 2.0) / 2.0 * Ts;
    coef[1] = pow(params[AF_P_tilt_sd], 2.0);
    coef[2] = Ts;
    coef[3] = params[AF_P_g];
}

void luinge_initial_state(const double coef[LUINGE_COEF_SIZE], const double acc0[3], double state[LUINGE_STATE_SIZE])
{
    level_on(acc0, state);
    state[4] = state[5] = coef[1];
}

Vec3 luinge_step(double state[LUINGE_STATE_SIZE], double Q, double R, double Ts, const double gyr[3],
                 const double acc[3])
{
    Quat q = quat_multiply(quat_load(state), rotvec_quat(gyr[0] * Ts, gyr[1] * Ts, gyr[2] * Ts));
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double norm = sqrt(a0 * a0 + a1 * a1 + a2 * a2);
    if (norm > 0.0) {
        Vec3 v = quat_rotate(q, (Vec3){a0 / norm, a1 / norm, a2 / norm}); /* measured up, earth frame */
        double horizontal = sqrt(v.x * v.x + v.y * v.y);
        double scale = horizontal > 1e-15 ? atan2(horizontal, v.z) / horizontal : 1.0;
        double z0 = v.y * scale, z1 = -v.x * scale; /* tilt difference about earth x and y, rad */
        double p0 = state[4] + Q, p1 = state[5] + Q;
        double k0 = p0 / (p0 + R), k1 = p1 / (p1 + R);
        state[4] = (1.0 - k0) * p0;
        state[5] = (1.0 - k1) * p1;
        q = quat_multiply(rotvec_quat(k0 * z0, k1 * z1, 0.0), q);
    }
    q = quat_normalized(q);
    quat_store(q, state);
    return up_in_sensor(q);
}

void luinge_run(double state[LUINGE_STATE_SIZE], const double coef[LUINGE_COEF_SIZE], const double gyr[3],
                const double acc[3], double gravity[3], double quat[4])
{
    Vec3 up = luinge_step(state, coef[0], coef[1], coef[2], gyr, acc);
    write_sample(gravity, quat, coef[3], up, state);
}
