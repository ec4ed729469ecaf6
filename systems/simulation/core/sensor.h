/* sensor.h: the IMU sensor model, ideal motion signals in, measured signals out (Rizun eqs. 1-2):
 * gyro y_g = (I + S) omega + n + b, accelerometer y_a = f + n_a + acc_offset, magnetometer
 * y_m = (I + S_m) m + n_m + mag_offset; white noise of one-sided densities, per-sample s.d. density*sqrt(fs/2).
 * Bound into Python by systems/simulation/sensor_model.py (ImuModel). */
#ifndef SIM_SENSOR_H
#define SIM_SENSOR_H

#include <stddef.h>

/* delta_n: gyro noise density, rad/s/sqrt(Hz); gyr_offset: b, rad/s; gyr_scale: S, row-major (row
 * i: what axis i adds of each true rate component); acc_noise: m/s^2/sqrt(Hz); acc_offset: m/s^2;
 * latency: how long gyr and acc lag the motion, s (sim/delay_line.h); mag_noise: uT/sqrt(Hz);
 * mag_offset: hard iron, uT; mag_soft_iron: soft iron S_m, row-major (row i: what axis i adds of each
 * true field component) */
typedef struct {
    double delta_n, gyr_offset[3], gyr_scale[9], acc_noise, acc_offset[3], latency, mag_noise, mag_offset[3],
        mag_soft_iron[9];
} ImuParams;

#define IMU_VECTOR_SIZE 31 /* ImuModel.vector's numbers */

/* The parameters of ImuModel.vector v, in ImuParams' order: delta_n, gyr_offset (3), gyr_scale (9,
 * row-major), acc_noise, acc_offset (3), latency, mag_noise, mag_offset (3),
 * mag_soft_iron (9, row-major); checked (imu_check): 0, or
 * -1 with the message. */
int imu_from_vector(const double v[IMU_VECTOR_SIZE], ImuParams *p, char *message, size_t size);

/* ImuModel's refusals: 0, or -1 with the message. */
int imu_check(const ImuParams *p, char *message, size_t size);
/* the refusal of a vector parameter (gyr_offset, acc_offset, mag_offset: 3 numbers; gyr_scale,
 * mag_soft_iron: 3x3)
 * that is not all finite numbers of its shape, its value written as repr: -1 with the message */
int imu_refuse_vector(const char *name, const char *repr, char *message, size_t size);
/* measured gyr (rad/s) and acc (m/s^2) from the true rate omega, specific force f and 6 unit normals
 * (gyro, then accelerometer) at sample rate fs (Hz) */
void imu_measure(const ImuParams *p, const double omega[3], const double f[3], const double noise[6], double fs,
                 double gyr[3], double acc[3]);
/* measured field (uT) from the true field m (uT, sensor coordinates) and 3 unit normals */
void imu_measure_mag(const ImuParams *p, const double m[3], const double noise[3], double fs, double mag[3]);
/* n samples of imu_measure: omega, f, gyr, acc n rows of 3, noise n rows of 6 */
void imu_measure_run(const ImuParams *p, const double *omega, const double *f, const double *noise, size_t n,
                     double fs, double *gyr, double *acc);
/* n samples of imu_measure_mag: m, noise, mag n rows of 3 */
void imu_measure_mag_run(const ImuParams *p, const double *m, const double *noise, size_t n, double fs, double *mag);

#endif
