/* lever_arm.h: the normal equations of the offline lever-arm fit (blocks/stages/lever_arm.py tells
 * the model): a sensor at r (m, sensor coordinates) from a fixed centre of rotation reads, beside
 * gravity, alpha x r + w x (w x r). */
#ifndef AF_LEVER_ARM_H
#define AF_LEVER_ARM_H

#include <stddef.h>

/* lever_arm_sums: over n samples, gyr (n x 3, rad/s, sample k the mean rate over the Ts s before t_k) and
 * acc (n x 3, m/s^2, at t_k), the least-squares problem y = X.r + (a constant per window): y = R_k.a_k and
 * X = R_k.A_k, R_k the orientation integrated from gyr (the identity before the first sample), A_k.r =
 * alpha_k x r + w_k x (w_k x r) with w_k and alpha_k from the gyro's mean rates over the span samples before
 * t_k and the span after (w their mean, alpha their difference over span Ts; rows beyond the recording its
 * first or last). In consecutive windows of `window` samples (the last holds those left over) y and X are
 * freed of their means; normal = sum X^T.X (3 x 3, row-major), moment = sum X^T.y (3) and *total = sum |y|^2
 * over the samples so freed. n >= 1, span >= 1, window >= 1, Ts > 0. */
void lever_arm_sums(size_t n, const double *gyr, const double *acc, double Ts, size_t span, size_t window,
                    double normal[9], double moment[3], double *total);

/* lever_arm_removed: out (n x 3, m/s^2) = acc less A_k.r (A_k as lever_arm_sums takes it) for r (3, m, sensor
 * coordinates); out may be acc. n >= 1, span >= 1, Ts > 0. */
void lever_arm_removed(size_t n, const double *gyr, const double *acc, double Ts, size_t span, const double r[3],
                       double *out);

#endif
