/* heading.h: heading from the magnetometer, freed of hard iron and of the magnetometer's delay,
 * guarded against disturbances; documented in blocks/stages/heading.py. */
#ifndef AF_HEADING_H
#define AF_HEADING_H

#include <stddef.h>

#include "af_params.h"
#include "quaternion.h"
#include "stages/fields.h"
#include "stages/hard_iron.h"
#include "stages/mag_delay.h"

/* The stage's own state: psi_c, the heading correction (rad); the drift estimate: its level (rad, the unwrapped
 * field heading at the last block's middle), drift rate (rad/s), the level's variance, its covariance with the
 * rate and the rate's variance; the rate psi_c follows (rad/s); the last field heading, the field heading
 * unwrapped since the start; the block's sum of it, its samples and steps; the last block's steps; the blocks
 * since the start; the last two block means (the older first); the noise measure (mean |second difference|, rad)
 * and the blocks in it; the field in the earth frame before the turn by psi_c, through the guard's low-pass; the
 * reference norm (the field's unit) and dip (rad); the field samples since the start-up began; the candidate
 * field's norm, dip, field samples and smallest |q.q0| since it began, q0 the orientation then; the steps since
 * the start-up began; the step the candidate began at; the steps since the last field sample; the last step's
 * orientation (0: none yet). The magnetometer's noise, measured over its distinct samples (a held sample repeats
 * the last): the last sample as given; the last two distinct ones in the earth frame, the newest first; how many
 * there were; the sums of the absolute second differences of those, per axis; the steps spanned from the first to
 * the newest; the steps since the newest. The hard-iron fit's and the delay's states follow. */
#define HEADING_FIELDS(X)                                                                                          \
    X(psi_c, ) X(level, ) X(rate, ) X(var_level, ) X(covariance, ) X(var_rate, ) X(follow, ) X(h_last, )          \
    X(unwrapped, ) X(blk_sum, ) X(blk_n, ) X(blk_steps, ) X(blk_last, ) X(blocks, ) X(blk_mean, [2]) X(d2, [2])    \
    X(m_low, [3]) X(ref_norm, ) X(ref_dip, ) X(seen, ) X(cand_norm, ) X(cand_dip, ) X(cand_n, ) X(cand_dot, )      \
    X(cand_q0, [4]) X(steps, ) X(cand_start, ) X(gap, ) X(q_prev, [4]) X(m_last, [3]) X(noise_m, [2][3])           \
    X(noise_n, ) X(noise_abs, [3]) X(noise_span, ) X(noise_gap, )
typedef struct {
    HEADING_FIELDS(AF_DOUBLES)
    AfHardIron hard_iron;
    AfMagDelay mag_delay;
} AfHeading;
extern const AfField HEADING_STATE_FIELDS[];
extern const size_t HEADING_N_FIELDS;

/* Its coefficients at one step (IMU sample) time Ts. */
typedef struct {
    double q_psi;                                    /* delta_n^2/2: the heading's random walk (rad^2/s) */
    double q_rate;                                   /* sigma_motion^2/tau_reference: the drift rate's ((rad/s)^2/s) */
    double r_drift;                                  /* the field heading's noise density for the drift (rad^2 s) */
    double rate_max;                                 /* heading_drift: the largest drift rate, its prior s.d. (rad/s) */
    double block_steps;                              /* the noise measure's block: DRIFT_BLOCK_TAUS tau_heading */
    double a_block;                                  /* a block's least weight in it (block/tau_reference) */
    double rate_left;                                /* sigma_motion: the drift left to the pull alone (rad/s) */
    double rate_heading, rate_reference, rate_guard; /* Ts/tau_heading, Ts/tau_reference, Ts/tau_mag_guard */
    double a_heading, a_reference, a_guard;          /* 1 - exp(-Ts/tau) of each (the guard's 0 where unset) */
    double guard_online;                             /* 1: tau_mag_guard unset, from the noise (0: given) */
    double norm_tol, dip_tol, clip;                  /* mag_norm_tol, mag_dip_tol (rad), heading_clip (rad) */
    double new_steps;                                /* mag_new_time/Ts */
    double cos_half_turn;                            /* cos(mag_new_angle/2) */
    double delay;                                    /* mag_delay (s); NaN: estimated online */
    AfHardIronCoef hard_iron;
    AfMagDelayCoef mag_delay;
} AfHeadingCoef;

/* coefficients: from the stage's resolved parameters (AF_P_<name>) at Ts (s); 0, or -1 where one is
 * not finite (they overflow at this Ts; delay is NaN where mag_delay is unset). */
int heading_coefficients(const double params[AF_N_PARAMS], double Ts, AfHeadingCoef *coef);

/* initial_state: nothing seen yet. */
void heading_initial_state(AfHeading *state);

/* heading_step: q (the attitude filter's orientation, w x y z) turned by the updated heading correction
 * into out (may be q); *ok: whether the field m (a NaN: no sample this step) was used. state in place;
 * its hard_iron.offset is the hard-iron estimate, mag_delay.delay the delay allowed for (s). (Rows in
 * and out by pointer: a quaternion returned by value goes through memory a double at a time and is read
 * back two at a time, which stalls.) */
void heading_step(AfHeading *state, const AfHeadingCoef *coef, const double q[4], const double m[3], double out[4],
                  int *ok);

/* heading_step over n samples: quat (rows of 4) and mag (rows of 3) in; out (rows of 4; may be quat),
 * accepted (0 or 1), offset (rows of 3: the hard-iron estimate after each) and delay (the delay
 * allowed for, s) out. */
void heading_run(AfHeading *state, const AfHeadingCoef *coef, size_t n, const double *quat, const double *mag,
                 double *out, unsigned char *accepted, double *offset, double *delay);

#endif
