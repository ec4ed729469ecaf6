/* tseng.h: the `tseng` method's earth-frame filter, C G_LA of Tseng et al.'s complementary
 * filter in the gyro-estimated earth frame (a fixed transfer function): the compensation C, the
 * inverse of the pair's chain G_LA G_A + G_H G_G, times the low-pass G_LA (eqs. 6-11), as
 * blocks/filters/tseng.py designs it with python-control (earth_filter); and the gyro branch
 * of the paper's own filter on Euler angles. */
#ifndef AF_TSENG_H
#define AF_TSENG_H

#include <stddef.h>

#include "filters/earth_filters.h"

#define TSENG_ORDER 5 /* states of the filter, at most MAX_ORDER */

typedef char tseng_order_fits[TSENG_ORDER <= MAX_ORDER ? 1 : -1];

/* The filter's state space, as control.ss(tseng.earth_filter()) realises it. */
void tseng_earth_filter(EarthFilter *out);

/* Roll and pitch (rad) integrated from roll0, pitch0 through the Z-Y-X Euler kinematics over n
 * gyro samples (n x 3, rad/s, each held over Ts s), forward Euler: the angles after each sample
 * into roll and pitch (n each). Singular where pitch reaches +-90 deg. */
void euler_rates(size_t n, const double *gyr, double Ts, double roll0, double pitch0, double *roll, double *pitch);

#endif
