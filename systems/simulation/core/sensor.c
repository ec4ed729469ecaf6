/* sensor.c: Python twin systems/simulation/sensor_model.py (ImuModel.__post_init__, measure,
 * measure_mag); the same operations in the same order. */
#include "sim/sensor.h"

#include <math.h>
#include <stdio.h>

#include "messages.h"

/* Python's repr of a tuple of 3 floats, "(1.0, nan, 0.0)" */
static const char *triple_repr(const double v[3], char out[3 * FLOAT_REPR_SIZE + 8]) {
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE], c[FLOAT_REPR_SIZE];
    snprintf(out, 3 * FLOAT_REPR_SIZE + 8, "(%s, %s, %s)", float_repr(v[0], a), float_repr(v[1], b),
             float_repr(v[2], c));
    return out;
}

int imu_check(const ImuParams *p, char *message, size_t size) {
    const char *names[4] = {"delta_n", "acc_noise", "latency", "mag_noise"};
    const double values[4] = {p->delta_n, p->acc_noise, p->latency, p->mag_noise};
    char repr[FLOAT_REPR_SIZE];
    for (int i = 0; i < 4; i++)
        if (!(isfinite(values[i]) && values[i] >= 0.0))
            return refuse(message, size, "%s must be finite and non-negative, got %s", names[i],
                          float_repr(values[i], repr));
    const char *vectors[3] = {"gyr_offset", "acc_offset", "mag_offset"};
    const double *components[3] = {p->gyr_offset, p->acc_offset, p->mag_offset};
    char tuple[3][3 * FLOAT_REPR_SIZE + 8];
    for (int i = 0; i < 3; i++)
        if (!(isfinite(components[i][0]) && isfinite(components[i][1]) && isfinite(components[i][2])))
            return refuse(message, size, "%s must be 3 finite numbers, got %s", vectors[i],
                          triple_repr(components[i], tuple[0]));
    for (int c = 0; c < 9; c++)
        if (!isfinite(p->gyr_scale[c]))
            return refuse(message, size, "gyr_scale must be 3\u00d73 finite numbers, got (%s, %s, %s)",
                          triple_repr(p->gyr_scale, tuple[0]), triple_repr(p->gyr_scale + 3, tuple[1]),
                          triple_repr(p->gyr_scale + 6, tuple[2]));
    return 0;
}

void imu_measure(const ImuParams *p, const double omega[3], const double f[3], const double noise[6], double fs,
                 double gyr[3], double acc[3]) {
    double scale = sqrt(fs / 2.0);
    const double *S = p->gyr_scale;
    for (int i = 0; i < 3; i++) {
        double added = omega[0] * S[3 * i] + omega[1] * S[3 * i + 1] + omega[2] * S[3 * i + 2]; /* omega @ S.T */
        gyr[i] = omega[i] + added + p->delta_n * scale * noise[i] + p->gyr_offset[i];
        acc[i] = f[i] + p->acc_noise * scale * noise[3 + i] + p->acc_offset[i];
    }
}

void imu_measure_mag(const ImuParams *p, const double m[3], const double noise[3], double fs, double mag[3]) {
    double scale = p->mag_noise * sqrt(fs / 2.0);
    for (int i = 0; i < 3; i++) mag[i] = m[i] + scale * noise[i] + p->mag_offset[i];
}
