/* native_online.c: for tests/test_native_stages.py, the C core's online estimator
 * (fmu_src/native/core/pipeline/online.h) driven over whole arrays, so that ctypes is called
 * once per run instead of once per sample. */
#include <string.h>

#include "pipeline/online.h"

#define OUTPUTS 17 /* per sample: quat 4, up 3, euler 3, offset 3, mag_offset 3, mag_delay 1 */

size_t online_size(void)
{
    return sizeof(AfOnline);
}

int online_init(AfOnline *est, const char *method, const double params[AF_N_PARAMS], int heading, int gyro_offset,
                double latency, const char *gyr_samples, const char *acc_samples, char *message, size_t size)
{
    AfConfig config = {method, {0}, heading, gyro_offset, latency, gyr_samples, acc_samples};
    memcpy(config.params, params, sizeof config.params);
    return af_online_init(est, &config, message, size);
}

/* n samples (gyr, acc, mag n x 3, Ts n): status[k] of each step, out[k] (OUTPUTS values) after
 * it; returns the number of samples stepped, fewer where a step ended in an error (its message). */
size_t online_run(AfOnline *est, size_t n, const double *gyr, const double *acc, const double *mag, const double *Ts,
                  int *status, double *out, char *message, size_t size)
{
    for (size_t k = 0; k < n; k++) {
        status[k] = af_online_step(est, gyr + 3 * k, acc + 3 * k, mag + 3 * k, Ts[k], message, size);
        if (status[k] < 0)
            return k;
        double *o = out + OUTPUTS * k;
        memcpy(o, est->quat, sizeof est->quat);
        memcpy(o + 4, est->up, sizeof est->up);
        memcpy(o + 7, est->euler, sizeof est->euler);
        memcpy(o + 10, est->offset, sizeof est->offset);
        memcpy(o + 13, est->mag_offset, sizeof est->mag_offset);
        o[16] = est->mag_delay;
    }
    return n;
}
