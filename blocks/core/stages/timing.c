/* timing.c: sample timing and latency (documented in blocks/stages/timing.py). */
#include "timing.h"

#include <math.h>
#include <string.h>

#include "messages.h"

const char *const GYR_SAMPLES[2] = {"mean", "point"};
const char *const ACC_SAMPLES[2] = {"point", "mean"};

/* 0, or -1 with the message unless value is one of the two allowed */
static int check_convention(const char *name, const char *value, const char *const allowed[2], char *message,
                            size_t size)
{
    char text[64], first[16], second[16];
    if (strcmp(value, allowed[0]) == 0 || strcmp(value, allowed[1]) == 0) return 0;
    return refuse(message, size, "%s must be %s or %s, got %s", name, str_repr(allowed[0], first, sizeof first),
                  str_repr(allowed[1], second, sizeof second), str_repr(value, text, sizeof text));
}

int check_samples(const char *gyr_samples, const char *acc_samples, char *message, size_t size)
{
    if (check_convention("gyr_samples", gyr_samples, GYR_SAMPLES, message, size)) return -1;
    return check_convention("acc_samples", acc_samples, ACC_SAMPLES, message, size);
}

int same_step(double Ts, double reference)
{
    return fabs(Ts - reference) <= STEP_TOLERANCE * reference;
}

static double grid_index(double start, double Ts, double t)
{
    return floor((t - start) / Ts + GRID_TOLERANCE);
}

double grid_samples(double start, double Ts, double t, double h)
{
    double before = grid_index(start, Ts, t), after = grid_index(start, Ts, t + h);
    return after > before ? after - before : 0.0;
}

double grid_before(double start, double Ts, double t)
{
    return start + grid_index(start, Ts, t) * Ts;
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

void carry_forward_rows(size_t n, double *quat, double *gravity, const double *gyr, double latency)
{
    for (size_t k = 0; k < n; k++) {
        double *q = quat + 4 * k, *g = gravity + 3 * k;
        const double *w = gyr + 3 * k;
        Quat carried;
        Vec3 up;
        carry_forward(quat_load(q), (Vec3){g[0], g[1], g[2]}, (Vec3){w[0], w[1], w[2]}, latency, &carried, &up);
        quat_store(carried, q);
        g[0] = up.x, g[1] = up.y, g[2] = up.z;
    }
}

void interval_ends(size_t n, const double *gyr, const double *acc, double Ts, double *out)
{
    for (size_t k = 0; k < n; k++) {
        const double *w = gyr + 3 * k, *a = acc + 3 * k;
        Vec3 end = interval_end((Vec3){w[0], w[1], w[2]}, (Vec3){a[0], a[1], a[2]}, Ts);
        out[3 * k] = end.x, out[3 * k + 1] = end.y, out[3 * k + 2] = end.z;
    }
}
