/* luinge.c: Luinge's tilt Kalman filter (see luinge.h). */
#include "luinge.h"

#include <math.h>

#include "methods/mahony.h"

void luinge_coefficients(const double params[AF_N_PARAMS], double Ts, LuingeCoef *coef)
{
    *coef = (LuingeCoef){pow(params[AF_P_delta_n], 2.0) / 2.0 * Ts, pow(params[AF_P_tilt_sd], 2.0), Ts,
                         params[AF_P_g]};
}

void luinge_initial_state(const LuingeCoef *coef, const double acc0[3], LuingeState *state)
{
    *state = (LuingeState){level_on(acc0), {coef->R, coef->R}};
}

Vec3 luinge_step(LuingeState *state, double Q, double R, double Ts, const double gyr[3], const double acc[3])
{
    Quat q = quat_multiply(state->q, rotvec_quat(gyr[0] * Ts, gyr[1] * Ts, gyr[2] * Ts));
    double a0 = acc[0], a1 = acc[1], a2 = acc[2];
    double norm = sqrt(a0 * a0 + a1 * a1 + a2 * a2);
    if (norm > 0.0) {
        Vec3 v = quat_rotate(q, (Vec3){a0 / norm, a1 / norm, a2 / norm}); /* measured up, earth frame */
        double horizontal = sqrt(v.x * v.x + v.y * v.y);
        double scale = horizontal > 1e-15 ? atan2(horizontal, v.z) / horizontal : 1.0;
        double z0 = v.y * scale, z1 = -v.x * scale; /* tilt difference about earth x and y, rad */
        double p0 = state->P[0] + Q, p1 = state->P[1] + Q;
        double k0 = p0 / (p0 + R), k1 = p1 / (p1 + R);
        state->P[0] = (1.0 - k0) * p0;
        state->P[1] = (1.0 - k1) * p1;
        q = quat_multiply(rotvec_quat(k0 * z0, k1 * z1, 0.0), q);
    }
    state->q = quat_normalized(q);
    return up_in_sensor(state->q);
}

void luinge_run(LuingeState *state, const LuingeCoef *coef, const double gyr[3], const double acc[3],
                double gravity[3], double quat[4])
{
    Vec3 up = luinge_step(state, coef->Q, coef->R, coef->Ts, gyr, acc);
    write_sample(gravity, quat, coef->g, up, state->q);
}
