/* scale_error.h: the Wiener filter's candidate scale errors scored over a window of a recording, in
 * one pass (the batch path's choice of scale_error, blocks/stages/scale_error.py). */
#ifndef AF_SCALE_ERROR_H
#define AF_SCALE_ERROR_H

#include <stddef.h>

#include "methods/wiener_local.h"
#include "stages/prediction.h"

/* scale_error_errors: the block means of prediction_errors (prediction.h; horizon m, blocks of `block`
 * rows) of count Wiener filters with local densities (1 to PREDICTION_MAX_COUNT; coefs, sharing Ts,
 * a_avg and leak_v with warm) over a window of n rows of gyr (rad/s, freed of its offset) and acc
 * (m/s^2): the filter starts at rest on start (m/s^2, sensor frame) on row 0 and runs rows
 * [0, warm_up) with warm, then each candidate from that state over [warm_up, n); the rows predicted
 * are those from max(warm_up, m), the warm-up's estimates predicting the first. Candidate c's block
 * means at means + c ceil((n - a - m)/block), a = warm_up - m where warm_up >= m, else 0. gravity:
 * 3 n count doubles, work: 3 m count doubles. The number of blocks of each (0: no row to predict). */
size_t scale_error_errors(const WienerLocalCoef *warm, const WienerLocalCoef *coefs, size_t count, size_t n,
                          size_t warm_up, const double *gyr, const double *acc, const double start[3], size_t m,
                          size_t block, double *gravity, double *work, double *means);

#endif
