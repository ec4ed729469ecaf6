/* prediction.h: how well an estimate of gravity predicts the accelerometer a horizon later through
 * the gyro (the criterion by which the batch path chooses the Wiener filter's scale_error from a
 * recording, blocks/stages/scale_error.py). */
#ifndef AF_PREDICTION_H
#define AF_PREDICTION_H

#include <stddef.h>

/* prediction_error: the mean over k >= m of |a_k - R_k^T R_(k-m) g_(k-m)|^2 (m^2/s^4): a_k the
 * accelerometer (m/s^2) and g_k the estimate of gravity (m/s^2, pointing up), both sensor frame, n rows
 * of 3; R_k the sensor's orientation integrated from the gyro (gyr, n rows of 3, rad/s, sample k the
 * mean rate over the Ts s before t_k): R_k = R_(k-1) exp([w_k]x Ts), the identity before the first.
 * work: 3 m doubles, m >= 1. With no acceleration other than gravity it is the estimate's mean-square
 * error m samples before plus the gyro's drift over m samples; -1 where n <= m (no sample to predict). */
double prediction_error(size_t n, const double *gyr, const double *acc, const double *gravity, double Ts, size_t m,
                        double *work);

/* prediction_errors: the same squared differences, their means over consecutive blocks of `block` of the
 * k >= m in means (the last block holds those left over, block or fewer); the number of blocks, at most
 * ceil((n - m)/block) (0 where n <= m, m == 0 or block == 0). */
size_t prediction_errors(size_t n, const double *gyr, const double *acc, const double *gravity, double Ts, size_t m,
                         size_t block, double *work, double *means);

#define PREDICTION_MAX_COUNT 8 /* estimates prediction_errors_of scores at once, at most */

/* prediction_errors_of: prediction_errors of count estimates of gravity (1 to PREDICTION_MAX_COUNT) over the
 * same rows at once, the orientation integrated once: estimate c's n rows at gravity + c stride, its block
 * means at means + c ceil((n - m)/block); work: 3 m count doubles. The number of blocks of each. */
size_t prediction_errors_of(size_t count, size_t n, const double *gyr, const double *acc, const double *gravity,
                            size_t stride, double Ts, size_t m, size_t block, double *work, double *means);

#endif
