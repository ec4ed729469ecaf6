/* tseng_adaptive.c: Tseng's adaptive filter through the steps of its two modes
 * (sensor_frame_step, mahony_step). */
#include "tseng_adaptive.h"

#include <math.h>

void tseng_adaptive_coefficients(const double params[AF_N_PARAMS], const DiscreteFilter *disc,
                                 TsengAdaptiveCoef *coef)
{
    static const double unit_input[3] = {1.0, 0.0, 0.0};
    double X[3 * MAX_ORDER];
    rest_state(disc, unit_input, X);
    coef->disc = *disc;
    coef->tol = params[AF_P_tol];
    coef->g = params[AF_P_g];
    coef->k_P = params[AF_P_k_P];
    coef->k_I = params[AF_P_k_I];
    for (int j = 0; j < TSENG_ORDER; j++) coef->x_rest[j] = X[3 * j];
}

void tseng_adaptive_initial_state(const TsengAdaptiveCoef *coef, const double acc0[3], TsengAdaptiveState *state)
{
    for (int j = 0; j < TSENG_ORDER; j++)
        state->X[j] = (Vec3){coef->x_rest[j] * acc0[0], coef->x_rest[j] * acc0[1], coef->x_rest[j] * acc0[2]};
    state->mahony = (MahonyState){{1.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
}

void tseng_adaptive_run(TsengAdaptiveState *state, const TsengAdaptiveCoef *coef, const double gyr[3],
                        const double acc[3], double gravity[3], double quat[4])
{
    const DiscreteFilter *d = &coef->disc;
    double g = coef->g, norm = sqrt(acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]);
    if (fabs(norm - g) <= coef->tol) {
        sensor_frame_step(state->X, &state->mahony.q, gyr, acc, TSENG_ORDER, d->Ad, d->Bd, d->C, d->D, d->Ts,
                          gravity);
    } else {
        Vec3 up = mahony_step(&state->mahony, coef->k_P, coef->k_I, d->Ts, gyr, acc);
        for (int j = 0; j < TSENG_ORDER; j++)
            state->X[j] = (Vec3){coef->x_rest[j] * g * up.x, coef->x_rest[j] * g * up.y, coef->x_rest[j] * g * up.z};
        gravity[0] = g * up.x;
        gravity[1] = g * up.y;
        gravity[2] = g * up.z;
    }
    quat_store(state->mahony.q, quat);
}
