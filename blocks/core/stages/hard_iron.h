/* hard_iron.h: the magnetometer's hard-iron offset, fitted online as a sphere, documented in
 * blocks/stages/hard_iron.py (which holds the batch-only back_dated). */
#ifndef AF_HARD_IRON_H
#define AF_HARD_IRON_H

#include "af_params.h"
#include "quaternion.h"
#include "stages/fields.h"

/* The fit's state: the sums of 1, m, m.m^T (xx, xy, xz, yy, yz, zz), m.|m|^2, |m|^2, |m|^4 over the
 * field samples, forgotten over mag_cal_time; the offset in use (the field's unit); the steps the
 * fit, or the field as it is, has held steady; the latest samples' mean square distance from
 * either sphere, relative to its radius; the steps since the sums started afresh. */
#define HARD_IRON_FIELDS(X)                                                                                        \
    X(sums, [15]) X(offset, [3]) X(fit_steps, ) X(raw_steps, ) X(recent_fit, ) X(recent_raw, ) X(age, )
typedef struct {
    HARD_IRON_FIELDS(AF_DOUBLES)
} AfHardIron;
extern const AfField HARD_IRON_STATE_FIELDS[];
extern const size_t HARD_IRON_N_FIELDS;

/* Its coefficients at one step time Ts. */
typedef struct {
    double cal_steps;           /* mag_cal_time/Ts (steps; 0: no fit) */
    double spread_min, tol;     /* mag_cal_spread, mag_cal_tol */
    double a_cal, a_recent;     /* 1 - exp(-Ts/mag_cal_time) (0 when off), 1 - exp(-Ts/mag_cal_recent) */
    double rate_cal, rate_recent; /* their rates per step: Ts/mag_cal_time (0 when off), Ts/mag_cal_recent */
} AfHardIronCoef;

void hard_iron_coefficients(const double params[AF_N_PARAMS], double Ts, AfHardIronCoef *coef);

/* pull: 1 - exp(-gap*rate), a first-order low-pass's weight over gap steps; one_step its value for one. */
static inline double pull(double gap, double rate, double one_step)
{
    return gap == 1.0 ? one_step : 1.0 - exp(-gap * rate);
}

/* hard_iron_step: the field sample (mx, my, mz) (finite) into the offset estimate state->offset;
 * 1 when the offset was taken or dropped at this sample. gap: steps since the last field sample;
 * norm_tol, steady_steps: the heading guard's norm tolerance and mag_new_time in steps. (The
 * sample goes as three doubles, in registers: a 3-vector by value or by pointer goes through
 * memory, where a copy read two doubles at a time from stores of one stalls.) */
int hard_iron_step(AfHardIron *state, const AfHardIronCoef *coef, double mx, double my, double mz, double gap,
                   double norm_tol, double steady_steps);

/* hard_iron_removed: the field sample m less the offset estimate in use (m as it is with the fit off) */
static inline Vec3 hard_iron_removed(const AfHardIron *state, const AfHardIronCoef *coef, Vec3 m)
{
    if (coef->cal_steps <= 0.0)
        return m;
    return (Vec3){m.x - state->offset[0], m.y - state->offset[1], m.z - state->offset[2]};
}

#endif
