/* hard_iron.h: the magnetometer's hard-iron offset, fitted online as a sphere (the online part;
 * back_dated is batch only). Python twin: blocks/stages/hard_iron.py. */
#ifndef AF_HARD_IRON_H
#define AF_HARD_IRON_H

#include "af_params.h"
#include "quaternion.h"

#define HARD_IRON_STATE_SIZE 23  /* STATE_SIZE */
#define HARD_IRON_COEF_SIZE 6    /* COEF_SIZE */
#define HARD_IRON_STATE_OFFSET 15 /* OFFSET.start: the offset in use in 3 entries from here */

/* coefficients: [mag_cal_time/Ts, mag_cal_spread, mag_cal_tol, mag_cal_recent/Ts,
 * 1 - exp(-Ts/mag_cal_time) (0 when off), 1 - exp(-Ts/mag_cal_recent)]. */
void hard_iron_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[HARD_IRON_COEF_SIZE]);

/* pull: 1 - exp(-gap*rate), a first-order low-pass's weight over gap steps; one_step its value for one. */
double pull(double gap, double rate, double one_step);

/* hard_iron_step: the field sample m (finite) less the offset estimate after updating it; *changed: 1
 * when the offset was taken or dropped at this sample. gap: steps since the last field sample;
 * norm_tol, steady_steps: the heading guard's norm tolerance and mag_new_time in steps. */
Vec3 hard_iron_step(double state[HARD_IRON_STATE_SIZE], const double coef[HARD_IRON_COEF_SIZE], Vec3 m, double gap,
                    double norm_tol, double steady_steps, int *changed);

#endif
