/* heading.h: heading from the magnetometer, freed of hard iron and of the magnetometer's delay,
 * guarded against disturbances. Python twin: blocks/stages/heading.py. */
#ifndef AF_HEADING_H
#define AF_HEADING_H

#include "af_params.h"
#include "quaternion.h"
#include "stages/hard_iron.h"
#include "stages/mag_delay.h"

#define HEADING_STATE_SIZE (19 + HARD_IRON_STATE_SIZE + MAG_DELAY_STATE_SIZE) /* len(STATE_NAMES) */
#define HEADING_COEF_SIZE (10 + HARD_IRON_COEF_SIZE + MAG_DELAY_COEF_SIZE)
#define HARD_IRON 19                                  /* blocks.stages.hard_iron's state from here */
#define HARD_IRON_OFFSET (HARD_IRON + HARD_IRON_STATE_OFFSET) /* its offset estimate in 3 entries from here */
#define MAG_DELAY (HARD_IRON + HARD_IRON_STATE_SIZE)  /* blocks.stages.mag_delay's state from here */
#define MAG_DELAY_IN_USE (MAG_DELAY + MAG_DELAY_STATE_DELAY) /* the delay allowed for (s) */
#define HARD_IRON_COEF 10                             /* blocks.stages.hard_iron's coefficients from here */
#define MAG_DELAY_COEF (HARD_IRON_COEF + HARD_IRON_COEF_SIZE)

/* coefficients: [Ts/tau_heading, Ts/tau_reference, mag_norm_tol, mag_dip_tol, heading_clip,
 * mag_new_time/Ts, cos(mag_new_angle/2), 1 - exp(-Ts/tau_heading), 1 - exp(-Ts/tau_reference),
 * mag_delay (s; NaN: estimated online)], then hard_iron's and mag_delay's. */
void heading_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[HEADING_COEF_SIZE]);

/* initial_state: nothing seen yet. */
void heading_initial_state(double state[HEADING_STATE_SIZE]);

/* heading_step: q (the attitude filter's orientation) turned by the updated heading correction;
 * *ok: whether the field m_sensor (a NaN: no sample this step) was used. state in place. */
Quat heading_step(double state[HEADING_STATE_SIZE], const double coef[HEADING_COEF_SIZE], Quat q, Vec3 m_sensor,
                  int *ok);

#endif
