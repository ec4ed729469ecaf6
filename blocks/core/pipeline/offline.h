/* offline.h: the batch-only offline smoother of a method (blocks.pipeline.batch with
 * offline=True): the method's earth-frame filter forward in time, then backward over the
 * forward gravity estimate, which for `wiener` is the non-causal Wiener smoother.
 * Units: gyr rad/s (sample k the mean rate over the sample time before it), acc and gravity
 * m/s^2, q sensor -> earth [w, x, y, z]; arrays row-major. */
#ifndef AF_OFFLINE_H
#define AF_OFFLINE_H

#include <stddef.h>

#include "methods/registry.h"

/* The smoother over n >= 1 samples gyr, acc (n x 3): the stepper's method runs forward from
 * rest on initial_gravity (m/s^2, sensor coordinates, before the first sample), then backward
 * in time over the forward gravity estimate, from rest on its last row; gravity (n x 3) is the
 * backward estimate and quat (n x 4) the forward orientation levelled onto it (level_onto).
 * wiener's local densities (KERNEL_WIENER_LOCAL) run both passes at the lower of the break
 * frequencies the densities give forward and backward in time (each pass from rest on its
 * first accelerometer row, the forward one on initial_gravity); omega: n values of scratch. */
void offline_smooth(const AfStepper *stepper, size_t n, const double *gyr, const double *acc,
                    const double initial_gravity[3], double *gravity, double *quat, double *omega);

#endif
