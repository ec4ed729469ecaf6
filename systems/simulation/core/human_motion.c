/* human_motion.c: HumanMotion's exact steps, a grid cell each, and its stream over any intervals of the grid. */
#include "human_motion.h"

#include <math.h>
#include <string.h>

#include "closed_form.h"
#include "messages.h"
#include "quaternion.h"
#include "noise.h"

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
    for (int i = 0; i < 3; i++) coef[6 + i] = p->lever[i];
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
    double w0[3] = {state[3], state[4], state[5]}, turn[4];
    for (int i = 3; i < 6; i++) state[i] = phi_w * state[i] + sig_w * noise[i];
    Quat dq = rotvec_quat(state[3] * Ts, state[4] * Ts, state[5] * Ts);
    Quat q = quat_normalized(quat_multiply((Quat){state[6], state[7], state[8], state[9]}, dq));
    Vec3 f = quat_rotate((Quat){q.w, -q.x, -q.y, -q.z}, specific);
    out[0] = state[3], out[1] = state[4], out[2] = state[5];
    out[3] = f.x, out[4] = f.y, out[5] = f.z;
    quat_store(dq, turn);
    lever_force(c + 6, w0, state + 3, turn, Ts, out + 3);
    out[6] = q.w, out[7] = q.x, out[8] = q.y, out[9] = q.z;
    state[6] = q.w, state[7] = q.x, state[8] = q.y, state[9] = q.z;
}

void human_run(double state[HUMAN_N_STATES], const double *noise, size_t n, const double coef[HUMAN_N_COEF],
               double *out) {
    for (size_t k = 0; k < n; k++) human_step(state, noise + 6 * k, coef, out + HUMAN_N_OUT * k);
}

void human_stream_init(HumanStream *stream, const HumanParams *params, double grid, uint64_t seed) {
    stream->params = *params;
    stream->seed = seed;
    stream->k = 0;
    stream->grid = grid;
    human_coefficients(params, 1.0 / grid, stream->coef);
    stream->coef[4] = grid;
    human_initial_state(stream->state);
    for (int i = 0; i < 3; i++) stream->v0[i] = 0.0, stream->acc[i] = 0.0;
    for (int i = 0; i < 4; i++) stream->q0[i] = stream->state[6 + i];
    stream->t = 0.0;
}

/* the next grid cell: its noise, its state at its start and end, its acceleration */
static void draw_cell(HumanStream *s) {
    double noise[MOTION_WIDTH], out[HUMAN_N_OUT];
    noise_normals(s->seed, MOTION, s->k++, MOTION_WIDTH, noise);
    for (int i = 0; i < 3; i++) s->v0[i] = s->state[i];
    for (int i = 0; i < 4; i++) s->q0[i] = s->state[6 + i];
    human_step(s->state, noise, s->coef, out);
    for (int i = 0; i < 3; i++) s->acc[i] = (s->state[i] - s->v0[i]) / s->grid;
}

int human_stream_step(HumanStream *s, double start, double end, double out[HUMAN_N_OUT], char *message,
                      size_t size) {
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE], c[FLOAT_REPR_SIZE];
    double G = s->grid;
    if (!(isfinite(start) && isfinite(end) && start <= end && start >= s->t - 1e-9 * fmax(1.0, s->t)))
        return refuse(message, size, "the human motion steps forward from time 0 s: not over (%s, %s] s after %s s",
                      float_repr(start, a), float_repr(end, b), float_repr(s->t, c));
    if (ceil(end / G) - (double)s->k > HUMAN_MAX_CELLS)
        return refuse(message, size, "a step to %s s needs more than %.0f cells of the human motion's grid (%s s)",
                      float_repr(end, a), HUMAN_MAX_CELLS, float_repr(G, b));
    if (ceil(end / G) > HUMAN_MAX_GRID)
        return refuse(message, size, "a step to %s s ends beyond the human motion's grid (%.0f cells of %s s)",
                      float_repr(end, a), HUMAN_MAX_GRID, float_repr(G, b));
    start = fmax(start, s->t);
    Quat turn = {1.0, 0.0, 0.0, 0.0};
    double dv[3] = {0.0, 0.0, 0.0}, t = start, w0[3] = {0.0, 0.0, 0.0};
    int rate_at_start = 0;
    for (;;) { /* the pieces of the cells (start, end] crosses */
        double cell_end = (double)s->k * G;
        if (!rate_at_start && start <= cell_end) { /* the rate of the cell (..., cell_end] start is in; 0 at time 0 */
            for (int i = 0; i < 3; i++) w0[i] = s->state[3 + i];
            rate_at_start = 1;
        }
        if (s->k > 0 && t < cell_end) {
            double piece_end = fmin(end, cell_end), tau = piece_end - t;
            turn = quat_multiply(turn, rotvec_quat(s->state[3] * tau, s->state[4] * tau, s->state[5] * tau));
            for (int i = 0; i < 3; i++) dv[i] += s->acc[i] * tau;
            t = piece_end;
        }
        if (end <= cell_end) break;
        draw_cell(s);
    }
    double h = end - start;
    if (!(h > 0.0) && (s->k == 0 || start >= (double)s->k * G)) draw_cell(s); /* the cell that starts at start */
    Quat q = quat_load(s->q0);
    if (end >= (double)s->k * G) q = quat_load(s->state + 6);
    else {
        double tau = end - (double)(s->k - 1) * G;
        q = quat_normalized(quat_multiply(q, rotvec_quat(s->state[3] * tau, s->state[4] * tau, s->state[5] * tau)));
    }
    double w[3] = {s->state[3], s->state[4], s->state[5]}, acc[3] = {s->acc[0], s->acc[1], s->acc[2]};
    double r[4];
    quat_store(quat_normalized(turn), r);
    if (h > 0.0) {
        rotation_vector(r, w);
        for (int i = 0; i < 3; i++) w[i] /= h, acc[i] = dv[i] / h;
    }
    Vec3 f = quat_rotate(quat_conjugate(q), (Vec3){acc[0], acc[1], acc[2] + s->params.g});
    out[0] = w[0], out[1] = w[1], out[2] = w[2];
    out[3] = f.x, out[4] = f.y, out[5] = f.z;
    quat_store(q, out + 6);
    lever_force(s->params.lever, w0, h > 0.0 ? s->state + 3 : w, r, h, out + 3);
    s->t = end;
    return 0;
}

/* whether the 4 doubles at q are a unit quaternion */
static int unit_quaternion(const double *q) {
    return fabs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0) < 1e-6;
}

int human_stream_validate(const HumanStream *s, const HumanStream *configured, char *message, size_t size) {
    if (memcmp(&s->params, &configured->params, sizeof s->params) != 0 || s->seed != configured->seed ||
        memcmp(&s->grid, &configured->grid, sizeof s->grid) != 0 ||
        memcmp(s->coef, configured->coef, sizeof s->coef) != 0)
        return refuse(message, size, "the human motion's parameters, seed or grid are not its configuration's");
    double G = s->grid, cells = (double)s->k;
    if (!(isfinite(s->t) && s->t >= 0.0))
        return refuse(message, size, "the human motion's time is not a finite time from 0 s");
    if (cells > HUMAN_MAX_GRID)
        return refuse(message, size, "the human motion's grid cells drawn (%.0f) are more than it draws (%.0f)", cells,
                      HUMAN_MAX_GRID);
    if (!(cells * G >= s->t * (1.0 - 1e-12) && (cells - 1.0) * G <= s->t + G * (1.0 + 1e-12)) ||
        (s->k == 0 && s->t != 0.0))
        return refuse(message, size, "the human motion's grid cells drawn (%.0f) are not those that reach its time",
                      cells);
    const double *groups[] = {s->state, s->v0, s->q0, s->acc};
    const int counts[] = {HUMAN_N_STATES, 3, 4, 3};
    for (int g = 0; g < 4; g++)
        for (int i = 0; i < counts[g]; i++)
            if (!isfinite(groups[g][i])) return refuse(message, size, "the human motion holds values not finite");
    if (!unit_quaternion(s->state + 6) || !unit_quaternion(s->q0))
        return refuse(message, size, "the human motion's orientations are not unit quaternions");
    return 0;
}
