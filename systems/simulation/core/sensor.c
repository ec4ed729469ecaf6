/* sensor.c: the IMU sensor model. */
#include "sensor.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "messages.h"

#define TRIPLE_REPR_SIZE (3 * FLOAT_REPR_SIZE + 8)

/* a tuple of 3 floats as Python writes it, "(1.0, nan, 0.0)" */
static const char *triple_repr(const double v[3], char out[TRIPLE_REPR_SIZE]) {
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE], c[FLOAT_REPR_SIZE];
    snprintf(out, TRIPLE_REPR_SIZE, "(%s, %s, %s)", float_repr(v[0], a), float_repr(v[1], b), float_repr(v[2], c));
    return out;
}

int imu_refuse_vector(const char *name, const char *repr, char *message, size_t size) {
    const char *shape = strcmp(name, "gyr_scale") == 0 || strcmp(name, "mag_soft_iron") == 0 ? "3\u00d73" : "3";
    return refuse(message, size, "%s must be %s finite numbers, got %s", name, shape, repr);
}

int imu_from_vector(const double v[IMU_VECTOR_SIZE], ImuParams *p, char *message, size_t size) {
    p->delta_n = v[0];
    memcpy(p->gyr_offset, v + 1, sizeof p->gyr_offset);
    memcpy(p->gyr_scale, v + 4, sizeof p->gyr_scale);
    p->acc_noise = v[13];
    memcpy(p->acc_offset, v + 14, sizeof p->acc_offset);
    p->latency = v[17];
    p->mag_noise = v[18];
    memcpy(p->mag_offset, v + 19, sizeof p->mag_offset);
    memcpy(p->mag_soft_iron, v + 22, sizeof p->mag_soft_iron);
    return imu_check(p, message, size);
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
    char tuple[3][TRIPLE_REPR_SIZE], matrix[3 * TRIPLE_REPR_SIZE + 8];
    for (int i = 0; i < 3; i++)
        if (!(isfinite(components[i][0]) && isfinite(components[i][1]) && isfinite(components[i][2])))
            return imu_refuse_vector(vectors[i], triple_repr(components[i], tuple[0]), message, size);
    const char *matrices[2] = {"gyr_scale", "mag_soft_iron"};
    const double *elements[2] = {p->gyr_scale, p->mag_soft_iron};
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < 9; c++)
            if (!isfinite(elements[i][c])) {
                snprintf(matrix, sizeof matrix, "(%s, %s, %s)", triple_repr(elements[i], tuple[0]),
                         triple_repr(elements[i] + 3, tuple[1]), triple_repr(elements[i] + 6, tuple[2]));
                return imu_refuse_vector(matrices[i], matrix, message, size);
            }
    return 0;
}

/* row i of the matrix M (row-major) times v */
static double row_times(const double *M, int i, const double v[3]) {
    return M[3 * i] * v[0] + M[3 * i + 1] * v[1] + M[3 * i + 2] * v[2];
}

void imu_measure(const ImuParams *p, const double omega[3], const double f[3], const double noise[6], double fs,
                 double gyr[3], double acc[3]) {
    double scale = sqrt(fs / 2.0);
    for (int i = 0; i < 3; i++) {
        double added = row_times(p->gyr_scale, i, omega); /* omega @ S.T */
        gyr[i] = omega[i] + added + p->delta_n * scale * noise[i] + p->gyr_offset[i];
        acc[i] = f[i] + p->acc_noise * scale * noise[3 + i] + p->acc_offset[i];
    }
}

void imu_measure_mag(const ImuParams *p, const double m[3], const double noise[3], double fs, double mag[3]) {
    double scale = p->mag_noise * sqrt(fs / 2.0);
    for (int i = 0; i < 3; i++) mag[i] = m[i] + row_times(p->mag_soft_iron, i, m) + scale * noise[i] + p->mag_offset[i];
}

void imu_measure_run(const ImuParams *p, const double *omega, const double *f, const double *noise, size_t n,
                     double fs, double *gyr, double *acc) {
    for (size_t k = 0; k < n; k++)
        imu_measure(p, omega + 3 * k, f + 3 * k, noise + 6 * k, fs, gyr + 3 * k, acc + 3 * k);
}

void imu_measure_mag_run(const ImuParams *p, const double *m, const double *noise, size_t n, double fs, double *mag) {
    for (size_t k = 0; k < n; k++) imu_measure_mag(p, m + 3 * k, noise + 3 * k, fs, mag + 3 * k);
}
