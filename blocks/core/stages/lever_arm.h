/* lever_arm.h: the normal equations of the offline lever-arm fit (blocks/stages/lever_arm.py tells
 * the model): a sensor at r (m, sensor coordinates) from a fixed centre of rotation reads, beside
 * gravity, alpha x r + w x (w x r). */
#ifndef AF_LEVER_ARM_H
#define AF_LEVER_ARM_H

#include <stddef.h>

/* lever_arm_terms: A (3 x 3, row-major) = [alpha]x + w w^T - |w|^2 I, so that A.r = alpha x r + w x (w x r), for
 * the rate w (rad/s) and the angular acceleration alpha (rad/s^2) */
static inline void lever_arm_terms(const double w[3], const double alpha[3], double A[9])
{
    double w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            A[3 * i + j] = w[i] * w[j] - (i == j ? w2 : 0.0);
    A[1] -= alpha[2], A[2] += alpha[1], A[5] -= alpha[0];
    A[3] += alpha[2], A[6] -= alpha[1], A[7] += alpha[0];
}

/* lever_arm_turned: X = R.A (3 x 3, row-major): the terms turned by R (row-major) into the frame y is taken in */
static inline void lever_arm_turned(const double R[9], const double A[9], double X[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            X[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] + R[3 * i + 2] * A[6 + j];
}

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
