/* offline.h: the batch-only offline smoother of a method (blocks.pipeline.batch with
 * offline=True): the method's earth-frame filter forward in time, then backward over the
 * forward gravity estimate, which for `wiener` is the non-causal Wiener smoother.
 * Units: gyr rad/s (sample k the mean rate over the sample time before it), acc and gravity
 * m/s^2, q sensor -> earth [w, x, y, z]; arrays row-major. */
#ifndef AF_OFFLINE_H
#define AF_OFFLINE_H

#include <stddef.h>

#include "methods/registry.h"
#include "stages/heading.h"

/* The smoother over n >= 1 samples gyr, acc (n x 3): the stepper's method runs forward from
 * rest on initial_gravity (m/s^2, sensor coordinates, before the first sample), then backward
 * in time over the forward gravity estimate, from rest on its last row; gravity (n x 3) is the
 * backward estimate and quat (n x 4) the gyro's orientation from the identity, levelled onto it
 * at each row (level_onto_gravity: the heading the gyro's).
 * wiener's local densities (KERNEL_WIENER_LOCAL) run both passes at the lower of the break
 * frequencies the densities give forward and backward in time (each pass from rest on its
 * first accelerometer row, the forward one on initial_gravity); omega: n values of scratch. */
void offline_smooth(const AfStepper *stepper, size_t n, const double *gyr, const double *acc,
                    const double initial_gravity[3], double *gravity, double *quat, double *omega);

/* The heading stage smoothed over n samples quat (n x 4, the attitude filter's orientation) and mag (n x 3; a row
 * with a NaN: no field sample): the stage forward in time with coef (its mag_delay given, not NaN), then
 * backward from the last row with the delay negated (a field that trails the gyro forward leads it backward).
 * Each row's heading correction is the two passes' psi_c averaged, each weighted by 1 - exp(-t/tau_heading),
 * t the time since its pass's first used field sample (a pass that has seen none weighs 0; the forward one
 * where neither has seen any); out (n x 4; may not be quat) the row turned by it about earth up. accepted:
 * whether either pass used the field (0 or 1); offset (n x 3) and delay (n, s): the forward pass's hard-iron
 * estimate and the delay allowed for. -1 (nothing written) where coef's delay is not a number, else 0. */
int offline_heading(const AfHeadingCoef *coef, size_t n, const double *quat, const double *mag, double *out,
                    unsigned char *accepted, double *offset, double *delay);

#endif
