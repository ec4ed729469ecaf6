/* tseng.h: the `tseng` method's earth-frame filter, C.G_LA of Tseng et al.'s complementary
 * filter in the gyro-estimated earth frame (a fixed transfer function).
 * Python twin: blocks/filters/tseng.py (earth_filter). Its coefficients are written from
 * Python into af_params.h (AF_TSENG_NUM, AF_TSENG_DEN; attitude_fmu.systems.fmi.native_tables). */
#ifndef AF_TSENG_H
#define AF_TSENG_H

#include "af_params.h"
#include "filters/earth_filters.h"

#define TSENG_ORDER (AF_TSENG_DEN_SIZE - 1) /* states of the filter, at most MAX_ORDER */

/* The filter's state space, as control.ss(tseng.earth_filter()). */
void tseng_earth_filter(EarthFilter *out);

#endif
