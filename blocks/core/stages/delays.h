/* delays.h: the per-span kernel of the magnetometer's delay measured over a whole recording
 * (blocks/stages/delays.py: mag_delay). */
#ifndef AF_DELAYS_H
#define AF_DELAYS_H

#include <stddef.h>

/* carry_spans: per span j, matrices[9 j ...] = R_D^T (row-major), R_D the sensor's turn from the
 * fractional sample index x0[j] to x1[j] (each held within [0, n - 1]). quat (n rows of 4, n >= 2):
 * the sensor at t_k integrated from gyr (n rows of 3, rad/s, over Ts s each); between samples k and
 * k + 1 it turns at gyro sample k + 1's rate. */
void carry_spans(size_t n, const double *quat, const double *gyr, double Ts, size_t spans, const double *x0,
                 const double *x1, double *matrices);

#endif
