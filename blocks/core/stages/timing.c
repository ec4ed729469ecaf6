/* timing.c: Python twin blocks/stages/timing.py; the same operations and messages. */
#include "timing.h"

#include <math.h>
#include <string.h>

#include "messages.h"

int check_samples(const char *gyr_samples, const char *acc_samples, char *message, size_t size)
{
    char text[64];
    if (strcmp(gyr_samples, "mean") != 0 && strcmp(gyr_samples, "point") != 0)
        return refuse(message, size, "gyr_samples must be 'mean' or 'point', got %s",
                      str_repr(gyr_samples, text, sizeof text));
    if (strcmp(acc_samples, "point") != 0 && strcmp(acc_samples, "mean") != 0)
        return refuse(message, size, "acc_samples must be 'point' or 'mean', got %s",
                      str_repr(acc_samples, text, sizeof text));
    return 0;
}

int same_step(double Ts, double reference)
{
    return fabs(Ts - reference) <= STEP_TOLERANCE * reference;
}

Vec3 interval_mean(Vec3 before, Vec3 now)
{
    return (Vec3){0.5 * (before.x + now.x), 0.5 * (before.y + now.y), 0.5 * (before.z + now.z)};
}

int check_latency(double latency, char *message, size_t size)
{
    char text[FLOAT_REPR_SIZE];
    if (isfinite(latency) && fabs(latency) <= MAX_LATENCY_S) return 0;
    return refuse(message, size, "latency must be a finite number of seconds within \302\261%g, got %s", MAX_LATENCY_S,
                  float_repr(latency, text));
}

void carry_forward(Quat q, Vec3 up, Vec3 gyr, double latency, Quat *q_out, Vec3 *up_out)
{
    Quat dq = rotvec_quat(gyr.x * latency, gyr.y * latency, gyr.z * latency);
    *q_out = quat_multiply(q, dq);
    *up_out = quat_rotate(quat_conjugate(dq), up);
}

Vec3 interval_end(Vec3 gyr, Vec3 acc, double Ts)
{
    Quat q;
    Vec3 up;
    carry_forward((Quat){1.0, 0.0, 0.0, 0.0}, acc, gyr, 0.5 * Ts, &q, &up);
    return up;
}
