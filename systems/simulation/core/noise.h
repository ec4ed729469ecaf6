/* noise.h: the simulations' one random generator, unit-normal noise streams from a seed:
 * Philox4x64-10 blocks of the counter (k, j, 0, 0) under the key (seed, stream), turned into
 * normals by Box-Muller (systems/simulation/noise.py documents it and binds it). */
#ifndef SIM_NOISE_H
#define SIM_NOISE_H

#include <stddef.h>
#include <stdint.h>

enum { MOTION = 0, SENSOR = 1, MAGNETOMETER = 2 }; /* the streams (the key's second word) */
#define MOTION_WIDTH 6       /* normals a sample of each stream draws (STREAM_WIDTHS) */
#define SENSOR_WIDTH 6
#define MAGNETOMETER_WIDTH 3

/* The Philox4x64-10 block of counter c under key k. */
void philox4x64(const uint64_t c[4], const uint64_t k[2], uint64_t out[4]);
/* value as a seed: 0, or -1 with the refusal (a whole number in [0, 2**64)). */
int check_seed(long long value, uint64_t *seed, char *message, size_t size);
/* the refusal of a seed that is not a whole number in [0, 2**64), given as its Python repr: -1 */
int refuse_seed(const char *repr, char *message, size_t size);
/* The width unit normals of sample k of a stream under seed. */
void noise_normals(uint64_t seed, uint64_t stream, uint64_t k, size_t width, double *out);
/* n samples first, first + 1, ... (modulo 2**64) of a stream: n rows of width normals, row-major */
void noise_fill(uint64_t seed, uint64_t stream, uint64_t first, size_t n, size_t width, double *out);

#endif
