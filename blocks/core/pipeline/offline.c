/* offline.c: the offline smoother (see offline.h). */
#include "pipeline/offline.h"

#include <math.h>
#include <string.h>

#include "filters/sensor_frame.h"
#include "quaternion.h"

/* the gyro sample that turns the frame from sample n - k to n - 1 - k in a pass backward in time, k = 0 ... n - 1:
 * -gyr[n - k] (0 for k = 0, before the first step) */
static void time_reversed_sample(size_t n, const double *gyr, size_t k, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = k == 0 ? 0.0 : -gyr[3 * (n - k) + i];
}

/* One pass of the stepper over n samples, forward (the rows as given) or backward in time (row k
 * of the pass is row n - 1 - k, turned by time_reversed_sample), from rest on start; the pass's
 * row k of the gravity estimate into gravity at row n - 1 - k when backward (each row of acc is
 * read before it is written, so acc may be gravity). wiener's local densities: at the break
 * frequencies omega (rows as the pass's, NULL: the local ones), and where used is not NULL the
 * ones used into it (rows as the pass's). */
static void pass(const AfStepper *s, size_t n, const double *gyr, const double *acc, int backward,
                 const double start[3], const double *omega, double *used, double *gravity)
{
    double state[AF_STEPPER_STATE_MAX], g[3], q[4];
    stepper_initial_state(s, start, state);
    for (size_t k = 0; k < n; k++) {
        size_t row = backward ? n - 1 - k : k;
        double turn[3];
        if (backward)
            time_reversed_sample(n, gyr, k, turn);
        else
            memcpy(turn, gyr + 3 * k, sizeof turn);
        if (s->kernel == KERNEL_WIENER_LOCAL) {
            wiener_local_rows((WienerLocalState *)(void *)state, &s->coef.wiener_local, 1, turn, acc + 3 * row,
                              omega != NULL ? omega + row : NULL, g, q, used != NULL ? used + row : NULL);
        } else {
            stepper_run(s, state, turn, acc + 3 * row, g, q);
        }
        memcpy(gravity + 3 * row, g, sizeof g);
    }
}

void offline_smooth(const AfStepper *stepper, size_t n, const double *gyr, const double *acc,
                    const double initial_gravity[3], double *gravity, double *quat, double *omega)
{
    const double *imposed = NULL;
    double last[3];
    if (stepper->kernel == KERNEL_WIENER_LOCAL) {
        /* the break frequencies of the local densities forward, then the lower of those and the
         * backward ones; gravity and quat serve as scratch meanwhile */
        double *backward = quat; /* n values at least (n x 4) */
        pass(stepper, n, gyr, acc, 0, initial_gravity, NULL, omega, gravity);
        memcpy(last, acc + 3 * (n - 1), sizeof last);
        pass(stepper, n, gyr, acc, 1, last, NULL, backward, gravity);
        for (size_t k = 0; k < n; k++)
            omega[k] = fmin(omega[k], backward[k]);
        imposed = omega;
    }
    pass(stepper, n, gyr, acc, 0, initial_gravity, imposed, NULL, gravity);
    memcpy(last, gravity + 3 * (n - 1), sizeof last);
    pass(stepper, n, gyr, gravity, 1, last, imposed, NULL, gravity);
    /* the orientation: the gyro's, levelled onto the smoothed gravity at each row (as a stepper does onto its
     * own estimate): the few large corrections of a pass's first rows in motion turn no heading into it */
    Quat q = {1.0, 0.0, 0.0, 0.0};
    const double Ts = stepper->Ts;
    for (size_t k = 0; k < n; k++) {
        const double *w = gyr + 3 * k, *g = gravity + 3 * k;
        q = level_onto_gravity(q, rotvec_quat(w[0] * Ts, w[1] * Ts, w[2] * Ts), (Vec3){g[0], g[1], g[2]});
        quat_store(q, quat + 4 * k);
    }
}

/* the heading correction (rad) that turned q into out about earth up: psi of out (x) q^-1 = Rz(psi) */
static double correction(const double q[4], const double out[4])
{
    Quat d = quat_multiply(quat_load(out), quat_conjugate(quat_load(q)));
    return 2.0 * atan2(d.z, d.w);
}

/* a pass's weight, t the steps since its first used field sample (negative: none yet) */
static double pass_weight(double steps, const AfHeadingCoef *coef)
{
    return steps < 0.0 ? 0.0 : 1.0 - exp(-(steps + 1.0) * coef->rate_heading);
}

int offline_heading(const AfHeadingCoef *coef, size_t n, const double *quat, const double *mag, double *out,
                    unsigned char *accepted, double *offset, double *delay)
{
    if (isnan(coef->delay))
        return -1;
    AfHeading state;
    heading_initial_state(&state);
    heading_run(&state, coef, n, quat, mag, out, accepted, offset, delay);
    size_t first = 0; /* the forward pass's first used field sample (n: none) */
    while (first < n && !accepted[first])
        first++;
    AfHeadingCoef back = *coef;
    back.delay = -coef->delay;
    heading_initial_state(&state);
    size_t last = n; /* the backward pass's first used field sample (the latest row) */
    for (size_t j = 0; j < n; j++) {
        size_t k = n - 1 - j;
        double q_back[4];
        int ok;
        heading_step(&state, &back, quat + 4 * k, mag + 3 * k, q_back, &ok);
        if (ok && last == n)
            last = k;
        double forward = correction(quat + 4 * k, out + 4 * k);
        double w_f = pass_weight(first <= k ? (double)(k - first) : -1.0, coef);
        double w_b = pass_weight(last < n ? (double)(last - k) : -1.0, coef);
        double psi = forward;
        if (w_b > 0.0)
            psi += w_b / (w_f + w_b) * remainder(state.psi_c - forward, 2.0 * AF_PI);
        quat_store(quat_multiply(rotvec_quat(0.0, 0.0, psi), quat_load(quat + 4 * k)), out + 4 * k);
        accepted[k] = (unsigned char)(accepted[k] | ok);
    }
    return 0;
}
