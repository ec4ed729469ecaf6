/* mag_delay.h: online estimate of the magnetometer's delay behind the gyro, documented in
 * blocks/stages/mag_delay.py. */
#ifndef AF_MAG_DELAY_H
#define AF_MAG_DELAY_H

#include "af_params.h"
#include "quaternion.h"
#include "stages/fields.h"

#define MAG_SPAN_S 0.25       /* s: the field is compared with the gyro over about this long */
#define MAG_DELAY_REACH_S 0.1 /* s: the largest delay looked for */
#define MAG_DELAY_SIGMAS 3.0  /* a delay is taken only this many standard errors or more from 0 */
#define MAG_DELAY_MIN_S 5.0   /* s of accepted field samples in the sums before a delay is taken */
#define MAG_DELAY_CLEAN_S 0.75 /* s: a sample enters the sums once the guard took every one this long (3 spans) */

/* The estimate's state: the last field sample (sensor frame, hard iron removed), the rate at it
 * (rad/s), the integrated rate since it (rad), the time since it (s), 1 once there was one;
 * y = L[dm/dt + w x m] and j = L[dw/dt x m]; the sums of y.j dt, |j|^2 dt, |y|^2 dt and dt,
 * forgotten over tau_mag_delay; the delay in use (s); the time since the guard last refused a
 * field sample (s). */
#define MAG_DELAY_FIELDS(X)                                                                                        \
    X(last_m, [3]) X(last_w, [3]) X(turn, [3]) X(since, ) X(seen, ) X(y, [3]) X(j, [3]) X(sums, [4]) X(delay, )    \
    X(clean, )
typedef struct {
    MAG_DELAY_FIELDS(AF_DOUBLES)
} AfMagDelay;
extern const AfField MAG_DELAY_STATE_FIELDS[];
extern const size_t MAG_DELAY_N_FIELDS;

/* Its coefficients at one step time Ts. */
typedef struct {
    double Ts;     /* s */
    double a;      /* 1/MAG_SPAN_S (rad/s), the low-passes' corner */
    double rate;   /* 1/tau_mag_delay (1/s), the sums' forgetting */
    double lag, forget, weight; /* over one step, the usual interval between field samples: exp(-a Ts),
                                   exp(-Ts/tau_mag_delay), (1 - exp(-a Ts))/Ts (1/s) */
} AfMagDelayCoef;

void mag_delay_coefficients(const double params[AF_N_PARAMS], double Ts, AfMagDelayCoef *coef);

/* turn: every step, the step's rotation (rad) added to the integrated rate. */
static inline void mag_delay_turn(AfMagDelay *state, const AfMagDelayCoef *coef, Vec3 rotation)
{
    state->turn[0] += rotation.x;
    state->turn[1] += rotation.y;
    state->turn[2] += rotation.z;
    state->since += coef->Ts;
}

/* restart: every sample forgotten, the delay in use reset to 0 (a hard-iron offset taken or dropped). */
void mag_delay_restart(AfMagDelay *state);

/* field_sample: a field sample m = (mx, my, mz) (sensor frame, hard iron removed) with the step's rate
 * w = (wx, wy, wz) (rad/s; as doubles, in registers, like hard_iron_step's);
 * the interval since the last one enters the estimate when use (the guard accepted it) and the
 * guard accepted every field sample over the last MAG_DELAY_CLEAN_S (the low-passes then hold
 * no refused field: a disturbance's edge would pass for a delay). */
void mag_delay_field_sample(AfMagDelay *state, const AfMagDelayCoef *coef, double mx, double my, double mz, double wx,
                            double wy, double wz, int use);

#endif
