/* noise.h: the simulations' one random generator, unit-normal noise streams from a seed.
 * Python twin: systems/simulation/noise.py (which documents the generator: Philox4x64-10 blocks of
 * the counter (k, j, 0, 0) under the key (seed, stream), turned into normals by Box-Muller). The
 * same (seed, stream, k) gives the same bits in both. */
#ifndef SIM_NOISE_H
#define SIM_NOISE_H

#include <stddef.h>
#include <stdint.h>

enum { MOTION = 0, SENSOR = 1, MAGNETOMETER = 2 }; /* the streams (the key's second word) */
#define MOTION_WIDTH 6       /* normals a sample of each stream draws (STREAM_WIDTHS) */
#define SENSOR_WIDTH 6
#define MAGNETOMETER_WIDTH 3
#define NOISE_MAX_WIDTH 8    /* two blocks */

/* The Philox4x64-10 block of counter c under key k. */
void philox4x64(const uint64_t c[4], const uint64_t k[2], uint64_t out[4]);
/* value as a seed: 0, or -1 with the refusal (check_seed: a whole number in [0, 2**64)). */
int check_seed(long long value, uint64_t *seed, char *message, size_t size);
/* The width (<= NOISE_MAX_WIDTH) unit normals of sample k of a stream under seed. */
void noise_normals(uint64_t seed, uint64_t stream, uint64_t k, int width, double *out);

#endif
