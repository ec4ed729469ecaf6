/* tseng.c: Python twin blocks/filters/tseng.py (earth_filter), from the coefficients Python computes. */
#include "tseng.h"

typedef char tseng_order_fits[TSENG_ORDER <= MAX_ORDER ? 1 : -1]; /* MAX_ORDER holds the tseng filter */

void tseng_earth_filter(EarthFilter *out)
{
    state_space(AF_TSENG_NUM, AF_TSENG_NUM_SIZE, AF_TSENG_DEN, AF_TSENG_DEN_SIZE, out);
}
