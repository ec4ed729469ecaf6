/* noise.c: Philox4x64-10 and the Box-Muller transform, the simulations' one random generator. */
#include "noise.h"

#include <math.h>
#include <stdio.h>

#include "messages.h"

#define M0 UINT64_C(0xD2E7470EE14C6C93) /* Philox4x64's multipliers */
#define M1 UINT64_C(0xCA5A826395121157)
#define W0 UINT64_C(0x9E3779B97F4A7C15) /* its key increments (Weyl) */
#define W1 UINT64_C(0xBB67AE8584CAA73B)
#define LOW32 UINT64_C(0xFFFFFFFF)
#define ROUNDS 10
#define UNIT 0x1p-52
#define TWO_PI 6.283185307179586 /* 2.0 * math.pi */

/* high and low 64-bit words of the 128-bit product a*b */
static uint64_t mulhilo(uint64_t a, uint64_t b, uint64_t *low) {
    uint64_t a_lo = a & LOW32, a_hi = a >> 32, b_lo = b & LOW32, b_hi = b >> 32;
    uint64_t lo_lo = a_lo * b_lo, hi_lo = a_hi * b_lo, lo_hi = a_lo * b_hi;
    uint64_t cross = (lo_lo >> 32) + (hi_lo & LOW32) + lo_hi;
    *low = a * b;
    return a_hi * b_hi + (hi_lo >> 32) + (cross >> 32);
}

int refuse_seed(const char *repr, char *message, size_t size) {
    return refuse(message, size, "seed must be a whole number in [0, 2**64), got %s", repr);
}

int check_seed(long long value, uint64_t *seed, char *message, size_t size) {
    if (value < 0) {
        char repr[24];
        snprintf(repr, sizeof repr, "%lld", value);
        return refuse_seed(repr, message, size);
    }
    *seed = (uint64_t)value;
    return 0;
}

void philox4x64(const uint64_t c[4], const uint64_t k[2], uint64_t out[4]) {
    uint64_t c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3], k0 = k[0], k1 = k[1];
    for (int r = 0; r < ROUNDS; r++) {
        if (r) {
            k0 += W0;
            k1 += W1;
        }
        uint64_t lo0, lo1;
        uint64_t hi0 = mulhilo(M0, c0, &lo0), hi1 = mulhilo(M1, c2, &lo1);
        uint64_t n0 = hi1 ^ c1 ^ k0, n2 = hi0 ^ c3 ^ k1;
        c0 = n0, c1 = lo1, c2 = n2, c3 = lo0;
    }
    out[0] = c0, out[1] = c1, out[2] = c2, out[3] = c3;
}

static void box_muller(uint64_t word0, uint64_t word1, double z[2]) {
    double r = sqrt(-2.0 * log(((double)(word0 >> 12) + 0.5) * UNIT));
    double angle = TWO_PI * (((double)(word1 >> 12) + 0.5) * UNIT);
    z[0] = r * cos(angle);
    z[1] = r * sin(angle);
}

void noise_normals(uint64_t seed, uint64_t stream, uint64_t k, size_t width, double *out) {
    const uint64_t key[2] = {seed, stream};
    for (size_t j = 0; j < width / 4 + (width % 4 != 0); j++) {
        const uint64_t counter[4] = {k, (uint64_t)j, 0, 0};
        uint64_t w[4];
        double z[4];
        philox4x64(counter, key, w);
        box_muller(w[0], w[1], z);
        box_muller(w[2], w[3], z + 2);
        for (size_t lane = 0; lane < 4 && 4 * j + lane < width; lane++) out[4 * j + lane] = z[lane];
    }
}

void noise_fill(uint64_t seed, uint64_t stream, uint64_t first, size_t n, size_t width, double *out) {
    for (size_t row = 0; row < n; row++) noise_normals(seed, stream, first + (uint64_t)row, width, out + row * width);
}
