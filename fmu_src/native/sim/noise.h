/* noise.h: the simulations' one random generator, unit-normal noise streams from a seed.
 * Python twin: systems/simulation/noise.py (which documents the generator: Philox4x64-10 blocks of
 * the counter (k, j, 0, 0) under the key (seed, stream), turned into normals by Box-Muller). The
 * same (seed, stream, k) gives the same bits in both. */
#ifndef SIM_NOISE_H
#define SIM_NOISE_H

#include <stdint.h>

enum { MOTION = 0, SENSOR = 1, MAGNETOMETER = 2 }; /* the streams (the key's second word) */
#define MOTION_WIDTH 6       /* normals a sample of each stream draws (STREAM_WIDTHS) */
#define SENSOR_WIDTH 6
#define MAGNETOMETER_WIDTH 3
#define NOISE_MAX_WIDTH 8    /* two blocks */

/* The Philox4x64-10 block of counter c under key k. */
void philox4x64(const uint64_t c[4], const uint64_t k[2], uint64_t out[4]);
/* The width (<= NOISE_MAX_WIDTH) unit normals of sample k of a stream under seed. */
void noise_normals(uint64_t seed, uint64_t stream, uint64_t k, int width, double *out);

#endif
