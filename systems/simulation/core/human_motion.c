/* human_motion.c: HumanMotion's exact steps. */
#include "human_motion.h"

#include <math.h>

#include "messages.h"
#include "quaternion.h"
#include "noise.h"

int human_check(const HumanParams *p, char *message, size_t size) {
    const char *names[4] = {"delta_v", "omega_c", "rot_cutoff", "g"};
    const double values[4] = {p->delta_v, p->omega_c, p->rot_cutoff, p->g};
    char repr[FLOAT_REPR_SIZE];
    for (int i = 0; i < 4; i++)
        if (!(isfinite(values[i]) && values[i] > 0.0))
            return refuse(message, size, "%s must be a finite positive number, got %s", names[i],
                          float_repr(values[i], repr));
    if (!(isfinite(p->rot_rms) && p->rot_rms >= 0.0))
        return refuse(message, size, "rot_rms must be finite and non-negative, got %s", float_repr(p->rot_rms, repr));
    return 0;
}

void human_coefficients(const HumanParams *p, double fs, double coef[HUMAN_N_COEF]) {
    double Ts = 1.0 / fs;
    double phi_v = exp(-p->omega_c * Ts);
    double var_v = p->delta_v * p->delta_v * p->omega_c / 4.0; /* (1/2pi) int S_v dw of eq. 14 */
    double phi_w = exp(-p->rot_cutoff * Ts);
    coef[0] = phi_v;
    coef[1] = sqrt(var_v * (1 - phi_v * phi_v));
    coef[2] = phi_w;
    coef[3] = sqrt(p->rot_rms * p->rot_rms * (1 - phi_w * phi_w));
    coef[4] = Ts;
    coef[5] = p->g;
}

void human_initial_state(double state[HUMAN_N_STATES]) {
    for (int i = 0; i < HUMAN_N_STATES; i++) state[i] = 0.0;
    state[6] = 1.0;
}

void human_step(double state[HUMAN_N_STATES], const double noise[6], const double c[HUMAN_N_COEF],
                double out[HUMAN_N_OUT]) {
    double phi_v = c[0], sig_v = c[1], phi_w = c[2], sig_w = c[3], Ts = c[4], g = c[5];
    double v0 = phi_v * state[0] + sig_v * noise[0];
    double v1 = phi_v * state[1] + sig_v * noise[1];
    double v2 = phi_v * state[2] + sig_v * noise[2];
    Vec3 specific = {(v0 - state[0]) / Ts, (v1 - state[1]) / Ts, (v2 - state[2]) / Ts + g};
    state[0] = v0, state[1] = v1, state[2] = v2;
    for (int i = 3; i < 6; i++) state[i] = phi_w * state[i] + sig_w * noise[i];
    Quat dq = rotvec_quat(state[3] * Ts, state[4] * Ts, state[5] * Ts);
    Quat q = quat_normalized(quat_multiply((Quat){state[6], state[7], state[8], state[9]}, dq));
    Vec3 f = quat_rotate((Quat){q.w, -q.x, -q.y, -q.z}, specific);
    out[0] = state[3], out[1] = state[4], out[2] = state[5];
    out[3] = f.x, out[4] = f.y, out[5] = f.z;
    out[6] = q.w, out[7] = q.x, out[8] = q.y, out[9] = q.z;
    state[6] = q.w, state[7] = q.x, state[8] = q.y, state[9] = q.z;
}

void human_run(double state[HUMAN_N_STATES], const double *noise, size_t n, const double coef[HUMAN_N_COEF],
               double *out) {
    for (size_t k = 0; k < n; k++) human_step(state, noise + 6 * k, coef, out + HUMAN_N_OUT * k);
}

void human_stream_init(HumanStream *stream, const HumanParams *params, uint64_t seed) {
    stream->params = *params;
    stream->seed = seed;
    stream->k = 0;
    stream->h = 0.0;
    human_initial_state(stream->state);
}

void human_stream_step(HumanStream *stream, double h, double out[HUMAN_N_OUT]) {
    if (h != stream->h) {
        human_coefficients(&stream->params, 1.0 / h, stream->coef);
        stream->h = h;
    }
    double noise[MOTION_WIDTH];
    noise_normals(stream->seed, MOTION, stream->k++, MOTION_WIDTH, noise);
    human_step(stream->state, noise, stream->coef, out);
}
