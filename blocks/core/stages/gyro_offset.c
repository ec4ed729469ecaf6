/* gyro_offset.c: the gyroscope-offset estimator (documented in blocks/stages/gyro_offset.py). */
#include "stages/gyro_offset.h"

#include <math.h>
#include <string.h>

#include "methods/wiener_local.h"
#include "stages/lever_arm.h"
#include "quaternion.h"

#define OBSERVED 0.5    /* the least share of an offset's effect H must keep in a direction to update it */
#define CLIP_SIGMAS 4.0 /* innovations clipped at this many sigma_init */
#define SETTLE_TAUS 3.0 /* no update before this many tau_acc (the low-pass forgetting its start) */

#define STATE_FIELD(name, dims) AF_FIELD(AfGyroOffset, name)
const AfField GYRO_OFFSET_STATE_FIELDS[] = {GYRO_OFFSET_FIELDS(STATE_FIELD)};
const size_t GYRO_OFFSET_N_FIELDS = sizeof GYRO_OFFSET_STATE_FIELDS / sizeof GYRO_OFFSET_STATE_FIELDS[0];

int gyro_offset_coefficients(const double params[AF_N_PARAMS], double Ts, AfGyroOffsetCoef *coef)
{
    double tau_motion = params[AF_P_tau_motion], s2 = params[AF_P_sigma_motion] * params[AF_P_sigma_motion];
    double V = tau_motion > 0 ? s2 * Ts / tau_motion : 0.0;
    double delta_n = params[AF_P_delta_n];
    double noise_floor = REST_NOISE_SIGMAS * delta_n / sqrt(4 * params[AF_P_tau_short]);
    double wt = sqrt(2.0) / params[AF_P_tau_acc] * Ts;
    coef->Ts = Ts;
    coef->a_lp = 1.0 - exp(-Ts / params[AF_P_tau_lp]);
    coef->a_short = 1.0 - exp(-Ts / params[AF_P_tau_short]);
    coef->a_rest = 1.0 - exp(-Ts / params[AF_P_tau_rest]);
    coef->r = delta_n * delta_n / (2.0 * Ts);
    coef->rest_gyr = noise_floor > params[AF_P_rest_gyr] ? noise_floor : params[AF_P_rest_gyr];
    coef->rest_gyr_abs = params[AF_P_rest_gyr_abs];
    coef->rest_acc = params[AF_P_rest_acc];
    coef->rest_time = params[AF_P_rest_time];
    coef->P0 = params[AF_P_sigma_init] * params[AF_P_sigma_init];
    coef->V = V;
    coef->W = V > 0 ? s2 * s2 / V + s2 : 0.0;
    butterworth_zoh(wt, coef->Ad, coef->Bd);
    coef->tau_acc = sqrt(2.0) * Ts / wt;
    coef->settle = SETTLE_TAUS * coef->tau_acc;
    coef->clip = CLIP_SIGMAS * sqrt(coef->P0);
    double every = floor(1.0 / (ARM_RATE_HZ * Ts) + 0.5), tau_arm = params[AF_P_tau_arm];
    coef->arm_every = coef->a_arm = coef->arm_keep = coef->arm_floor = 0.0; /* no lever arm */
    if (V > 0 && tau_arm > 0) {
        coef->arm_every = every > 1.0 ? every : 1.0;
        coef->a_arm = 1.0 - exp(-coef->arm_every * Ts / ARM_HIGHPASS_S);
        coef->arm_keep = exp(-coef->arm_every * Ts / tau_arm);
        coef->arm_floor = ARM_SHOWN_MIN * ARM_SHOWN_MIN / (1.0 - coef->arm_keep);
    }
    return af_finite(coef, sizeof *coef, NULL) ? 0 : -1;
}

void gyro_offset_initial_state(const AfGyroOffsetCoef *coef, const double gyr0[3], const double acc0[3],
                               AfGyroOffset *state)
{
    memset(state, 0, sizeof *state);
    for (int i = 0; i < 3; i++) {
        state->lp_gyr[i] = state->short_gyr[i] = state->arm_gyr[i] = gyr0[i];
        state->lp_acc[i] = state->short_acc[i] = acc0[i];
        state->r_lp[0][4 * i] = 1.0; /* LP(R) settled on I */
        state->P[4 * i] = coef->P0;   /* P0 on the diagonal */
    }
    state->q[0] = 1.0;
}

/* lowpass: a column of the Butterworth's two state rows (value, rate) after the input x. Called column by
 * column with inputs held in variables: a loop over an array of inputs keeps the array on the stack,
 * stored a double at a time and read two at a time, which stalls the reads. */
static inline void lowpass(double *restrict value, double *restrict rate, double x, const double Ad[4],
                           const double Bd[2])
{
    double x0 = *value, x1 = *rate;
    *value = Ad[0] * x0 + Ad[1] * x1 + Bd[0] * x;
    *rate = Ad[2] * x0 + Ad[3] * x1 + Bd[1] * x;
}

static double dot(const double u[3], const double v[3])
{
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

/* M.v for M 3x3 row-major */
static void mat_vec(const double M[9], const double v[3], double out[3])
{
    out[0] = M[0] * v[0] + M[1] * v[1] + M[2] * v[2];
    out[1] = M[3] * v[0] + M[4] * v[1] + M[5] * v[2];
    out[2] = M[6] * v[0] + M[7] * v[1] + M[8] * v[2];
}

/* M^T.v for M 3x3 row-major */
static void mat_t_vec(const double M[9], const double v[3], double out[3])
{
    out[0] = M[0] * v[0] + M[3] * v[1] + M[6] * v[2];
    out[1] = M[1] * v[0] + M[4] * v[1] + M[7] * v[2];
    out[2] = M[2] * v[0] + M[5] * v[1] + M[8] * v[2];
}

static double clipped(double x, double clip)
{
    double low = -clip > x ? -clip : x;
    return clip < low ? clip : low;
}

/* scalar_update: Kalman update of the offset b (P its covariance, 3 x 3, both in place) from one
 * scalar measurement z of h.b with noise variance w */
static inline void scalar_update(double b[3], double P[9], const double h[3], double z, double w)
{
    double Ph[3];
    mat_vec(P, h, Ph);
    double inv_s = 1.0 / (dot(h, Ph) + w);
    double innovation = (z - dot(h, b)) * inv_s;
    for (int i = 0; i < 3; i++) {
        b[i] += Ph[i] * innovation;
        for (int j = i; j < 3; j++) { /* Ph[i].Ph[j] = Ph[j].Ph[i] exactly: each product once */
            double dP = Ph[i] * Ph[j] * inv_s;
            P[3 * i + j] -= dP;
            if (j != i)
                P[3 * j + i] -= dP;
        }
    }
}

/* across: a vector across v (not normalised): the axis least along v, crossed with v */
static void across(const double v[3], double e[3])
{
    if (fabs(v[0]) <= fabs(v[1]) && fabs(v[0]) <= fabs(v[2])) {
        e[0] = 0.0, e[1] = v[2], e[2] = -v[1];
    } else if (fabs(v[1]) <= fabs(v[2])) {
        e[0] = -v[2], e[1] = 0.0, e[2] = v[0];
    } else {
        e[0] = v[1], e[1] = -v[0], e[2] = 0.0;
    }
}

/* joint_update: Kalman update of the offset b (P its covariance, both in place) from two independent scalar
 * measurements: innovation nu[a] of g[a].b, variance w[a] (the 2 x 2 innovation covariance inverted in closed
 * form: one division) */
static inline void joint_update(double b[3], double P[9], const double g1[3], const double g2[3], const double nu[2],
                                const double w[2])
{
    double Pg1[3], Pg2[3];
    mat_vec(P, g1, Pg1);
    mat_vec(P, g2, Pg2);
    double s11 = dot(g1, Pg1) + w[0], s12 = dot(g1, Pg2), s22 = dot(g2, Pg2) + w[1];
    double inv_det = 1.0 / (s11 * s22 - s12 * s12);
    double i11 = s22 * inv_det, i12 = -s12 * inv_det, i22 = s11 * inv_det; /* S^-1 */
    double x1 = i11 * nu[0] + i12 * nu[1], x2 = i12 * nu[0] + i22 * nu[1];
    double K1[3], K2[3]; /* the gain P.G^T.S^-1, by columns */
    for (int i = 0; i < 3; i++) {
        b[i] += Pg1[i] * x1 + Pg2[i] * x2;
        K1[i] = Pg1[i] * i11 + Pg2[i] * i12;
        K2[i] = Pg1[i] * i12 + Pg2[i] * i22;
    }
    for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++) { /* P -= K.G.P, symmetric: each entry once */
            double dP = K1[i] * Pg1[j] + K2[i] * Pg2[j];
            P[3 * i + j] -= dP;
            if (j != i)
                P[3 * j + i] -= dP;
        }
}

/* motion_update: Kalman update of the offset b (P its covariance) from the turn of the low-passed
 * accelerometer from old to new (gyro frame); r_lp, rb_lp: LP(R) (row-major) and LP(R.b).
 * The turn rate plus Pi.LP(R.b^) measures H.b, H = Pi.LP(R) (the low-pass delays the turn after a
 * change of b^); the innovation is clipped per component. H has rank 2 at most (Pi projects across
 * gravity): measured in a basis (e0, e2) across gravity, each component u.e of the innovation measures
 * (H^T u).b with variance W |u|^2, the two independent. Only directions H keeps at least OBSERVED of
 * are used: the singular values of the 2 x 2 problem M.M^T (M = (e1, e2)^T.LP(R), e1 = |new| e0 of e2's
 * length k) in closed form. Where both are kept (most samples) the joint update takes both components
 * (the same update as one scalar update after the other along the singular directions); else the larger's
 * direction alone, where kept, is a scalar update. The basis and the directions are left unnormalised (a
 * scalar measurement scaled by a length, its variance by its square, updates alike) and the test is made
 * in squares: that keeps square roots and all but one division of the update off the path from one
 * sample's estimate to the next. */
static void motion_update(double b[3], double P[9], const double old[3], const double new[3], const double r_lp[9],
                          const double rb_lp[3], double Ts, double W, double clip)
{
    double n2 = dot(new, new);
    if (n2 == 0.0)
        return;
    double e0[3], e2[3];
    across(new, e0);
    e2[0] = new[1] * e0[2] - new[2] * e0[1];
    e2[1] = new[2] * e0[0] - new[0] * e0[2];
    e2[2] = new[0] * e0[1] - new[1] * e0[0];
    double q0 = dot(e0, e0), k2 = n2 * q0; /* |e0|^2, |e2|^2 */
    double s = 1.0 / (n2 * Ts);
    double turn[3] = {(old[1] * new[2] - old[2] * new[1]) * s, (old[2] * new[0] - old[0] * new[2]) * s,
                      (old[0] * new[1] - old[1] * new[0]) * s};
    double Lb[3];
    mat_vec(r_lp, b, Lb);
    double d[3] = {rb_lp[0] - Lb[0], rb_lp[1] - Lb[1], rb_lp[2] - Lb[2]}; /* LP(R.b) - LP(R).b, across gravity below */
    double along = dot(d, new) / n2;
    /* written out element by element, as below: an array filled in a loop is kept on the stack, stored a
     * double at a time and read back in pairs (a store-forwarding stall on the path to the next sample) */
    double e[3] = {clipped(turn[0] + d[0] - along * new[0], clip), clipped(turn[1] + d[1] - along * new[1], clip),
                   clipped(turn[2] + d[2] - along * new[2], clip)};
    double g1[3], g2[3]; /* H^T.e0, H^T.e2 */
    mat_t_vec(r_lp, e0, g1);
    mat_t_vec(r_lp, e2, g2);
    /* M.M^T = ((n2 g1.g1, |new| g1.g2), (|new| g1.g2, g2.g2)): both eigenvalues mean +- radius at least
     * OBSERVED^2 k2 where mean - OBSERVED^2 k2 >= radius >= 0 */
    double g12 = dot(g1, g2), p11 = n2 * dot(g1, g1), p22 = dot(g2, g2);
    double half = 0.5 * (p11 - p22), mean = 0.5 * (p11 + p22), least = OBSERVED * OBSERVED * k2;
    double spare = mean - least, p12_2 = n2 * g12 * g12;
    if (spare >= 0.0 && spare * spare >= half * half + p12_2) {
        double nu[2] = {dot(e0, e), dot(e2, e)}, w[2] = {W * q0, W * k2};
        joint_update(b, P, g1, g2, nu, w);
        return;
    }
    /* else the larger eigenvalue mean + radius's direction alone, where it is kept: its eigenvector in the
     * well-conditioned form (c, sn) in the basis (e1, e2), of length L */
    double norm = sqrt(n2), p12 = norm * g12, radius = sqrt(half * half + p12_2);
    if (mean + radius < least)
        return;
    double c, sn;
    if (half >= 0.0)
        c = half + radius, sn = p12;
    else
        c = p12, sn = radius - half;
    double L2 = c * c + sn * sn;
    if (L2 == 0.0)
        c = 1.0, sn = 0.0, L2 = 1.0;
    double cn = c * norm; /* u = c e1 + sn e2 = cn e0 + sn e2 */
    double u[3] = {cn * e0[0] + sn * e2[0], cn * e0[1] + sn * e2[1], cn * e0[2] + sn * e2[2]};
    double h[3] = {cn * g1[0] + sn * g2[0], cn * g1[1] + sn * g2[1], cn * g1[2] + sn * g2[2]}; /* H^T.u */
    scalar_update(b, P, h, dot(u, e) + dot(h, b), W * L2 * k2); /* the innovation u.e */
}

/* arm_accelerations: A.r = alpha x r + w x (w x r) */
static void arm_accelerations(const double w[3], const double alpha[3], const double r[3], double out[3])
{
    double wr[3] = {w[1] * r[2] - w[2] * r[1], w[2] * r[0] - w[0] * r[2], w[0] * r[1] - w[1] * r[0]};
    out[0] = alpha[1] * r[2] - alpha[2] * r[1] + w[1] * wr[2] - w[2] * wr[1];
    out[1] = alpha[2] * r[0] - alpha[0] * r[2] + w[2] * wr[0] - w[0] * wr[2];
    out[2] = alpha[0] * r[1] - alpha[1] * r[0] + w[0] * wr[1] - w[1] * wr[0];
}

/* arm_fit: one of the online lever arm's fit samples (every arm_every samples): y = R.acc (the accelerometer in
 * the gyro frame) and X = R.A (A.r = alpha x r + w x (w x r)), each less its low-pass over ARM_HIGHPASS_S
 * (gravity, and the slow turn the offset's error gives it), into forgetting sums; r = (X^T.X)^-1 X^T.y, the
 * arm (m, sensor coordinates), kept where it explains at least ARM_EXPLAINED of sum |y|^2 (rotation about a
 * fixed centre is then nearly all the motion) and at least ARM_SHOWN_MIN RMS, is at most ARM_MAX_M long, and
 * ARM_SAMPLES_MIN samples or more carry sum |y|^2, else none; none before the high-pass has settled. */
static void arm_fit(AfGyroOffset *state, const AfGyroOffsetCoef *coef, const double R[9], const double y[3],
                    const double w[3], const double alpha[3])
{
    double A[9], X[9], dy[3], dX[9];
    lever_arm_terms(w, alpha, A);
    lever_arm_turned(R, A, X);
    if (state->arm_time == 0.0) { /* the high-pass starts on its first sample */
        memcpy(state->arm_y, y, sizeof state->arm_y);
        memcpy(state->arm_x, X, sizeof state->arm_x);
    }
    for (int i = 0; i < 3; i++)
        dy[i] = y[i] - (state->arm_y[i] += coef->a_arm * (y[i] - state->arm_y[i]));
    for (int i = 0; i < 9; i++)
        dX[i] = X[i] - (state->arm_x[i] += coef->a_arm * (X[i] - state->arm_x[i]));
    static const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
    double keep = coef->arm_keep, *N = state->arm_normal, *B = state->arm_moment;
    for (int e = 0; e < 6; e++) { /* (X^T.X)[row][col] */
        int i = row[e], j = col[e];
        N[e] = keep * N[e] + dX[i] * dX[j] + dX[3 + i] * dX[3 + j] + dX[6 + i] * dX[6 + j];
    }
    for (int i = 0; i < 3; i++)
        B[i] = keep * B[i] + dX[i] * dy[0] + dX[3 + i] * dy[1] + dX[6 + i] * dy[2];
    double dy2 = dot(dy, dy);
    state->arm_total = keep * state->arm_total + dy2;
    state->arm_square = keep * state->arm_square + dy2 * dy2;
    state->arm_time += coef->arm_every * coef->Ts;
    state->arm[0] = state->arm[1] = state->arm[2] = 0.0;
    if (state->arm_time < ARM_HIGHPASS_S || !(state->arm_total > coef->arm_floor) ||
        !(state->arm_total * state->arm_total >= ARM_SAMPLES_MIN * state->arm_square))
        return;
    double ridge = ARM_RIDGE * (N[0] + N[3] + N[5]) / 3.0;
    double a = N[0] + ridge, b = N[1], c = N[2], d = N[3] + ridge, e = N[4], f = N[5] + ridge;
    double adj[6] = {d * f - e * e, c * e - b * f, b * e - c * d, a * f - c * c, b * c - a * e, a * d - b * b};
    double det = a * adj[0] + b * adj[1] + c * adj[2];
    if (!(det > 0.0))
        return;
    double r[3] = {(adj[0] * B[0] + adj[1] * B[1] + adj[2] * B[2]) / det,
                   (adj[1] * B[0] + adj[3] * B[1] + adj[4] * B[2]) / det,
                   (adj[2] * B[0] + adj[4] * B[1] + adj[5] * B[2]) / det};
    double Nr[3] = {N[0] * r[0] + N[1] * r[1] + N[2] * r[2], N[1] * r[0] + N[3] * r[1] + N[4] * r[2],
                    N[2] * r[0] + N[4] * r[1] + N[5] * r[2]};
    double explained = 2.0 * dot(r, B) - dot(r, Nr);
    if (explained >= ARM_EXPLAINED * state->arm_total && explained >= coef->arm_floor &&
        dot(r, r) <= ARM_MAX_M * ARM_MAX_M)
        memcpy(state->arm, r, sizeof state->arm);
}

/* unit: q scaled to unit norm where it is that to rounding (one Newton step), else exactly */
static Quat unit(Quat q)
{
    double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    if (fabs(n2 - 1.0) > 1e-9)
        return quat_normalized(q);
    double k = 1.5 - 0.5 * n2;
    return (Quat){q.w * k, q.x * k, q.y * k, q.z * k};
}

/* gyro_offset_step, a rest's sample taken as a measurement of the offset only where allowed; whether the rest
 * has held rest_time at the sample into *resting (NULL: not wanted) */
static inline void step(AfGyroOffset *state, const AfGyroOffsetCoef *coef, const double gyr[3], const double acc[3],
                        int allowed, double offset[3], double variance[3], double *acc_out, unsigned char *resting)
{
    double removed[3] = {0.0, 0.0, 0.0}; /* the lever arm's accelerations, removed from acc into acc_out */
    double Ts = coef->Ts, V = coef->V;
    /* the inputs read and the offset estimate b and its covariance P updated in place: copies on the stack,
     * stored a double at a time and read back two at a time by the vectorised code, stall the loads */
    double *b = state->b, *P = state->P;
    double dg2 = 0.0, da2 = 0.0, g2 = 0.0;
    for (int i = 0; i < 3; i++) {
        state->lp_gyr[i] += coef->a_lp * (gyr[i] - state->lp_gyr[i]);
        state->lp_acc[i] += coef->a_lp * (acc[i] - state->lp_acc[i]);
        state->short_gyr[i] += coef->a_short * (gyr[i] - state->short_gyr[i]);
        state->short_acc[i] += coef->a_short * (acc[i] - state->short_acc[i]);
        double dg = state->short_gyr[i] - state->lp_gyr[i], da = state->short_acc[i] - state->lp_acc[i];
        dg2 += dg * dg;
        da2 += da * da;
        g2 += state->lp_gyr[i] * state->lp_gyr[i];
    }
    int still = dg2 < coef->rest_gyr * coef->rest_gyr && da2 < coef->rest_acc * coef->rest_acc &&
                g2 < coef->rest_gyr_abs * coef->rest_gyr_abs;
    if (still) /* the gyro through tau_rest from the start of the rest (where it has long forgotten that start) */
        for (int i = 0; i < 3; i++)
            state->rest_gyr_mean[i] += (state->rest == 0.0 ? 1.0 : coef->a_rest) * (gyr[i] - state->rest_gyr_mean[i]);
    state->rest = still ? state->rest + Ts : 0.0;
    double old[3] = {state->acc_lp[0][0], state->acc_lp[0][1], state->acc_lp[0][2]};
    if (V > 0.0) { /* tracking while moving: the gyro frame and its low-passes */
        Quat q = unit(quat_multiply( /* turned by the corrected gyro */
            quat_load(state->q), rotvec_quat((gyr[0] - b[0]) * Ts, (gyr[1] - b[1]) * Ts, (gyr[2] - b[2]) * Ts)));
        quat_store(q, state->q);
        double t = state->t += Ts;
        /* the accelerometer, R.b and R (row-major) low-passed */
        double R[9];
        quat_matrix(q, R);
        Vec3 a = {R[0] * acc[0] + R[1] * acc[1] + R[2] * acc[2], R[3] * acc[0] + R[4] * acc[1] + R[5] * acc[2],
                  R[6] * acc[0] + R[7] * acc[1] + R[8] * acc[2]}; /* R.acc (mat_vec's sums, in variables) */
        Vec3 rb = {R[0] * b[0] + R[1] * b[1] + R[2] * b[2], R[3] * b[0] + R[4] * b[1] + R[5] * b[2],
                   R[6] * b[0] + R[7] * b[1] + R[8] * b[2]};
        double *acc_lp = state->acc_lp[0], *acc_rate = state->acc_lp[1];
        if (t <= coef->tau_acc) { /* the running mean, derivative row at rest */
            double w = Ts / t;
            acc_lp[0] += w * (a.x - acc_lp[0]);
            acc_lp[1] += w * (a.y - acc_lp[1]);
            acc_lp[2] += w * (a.z - acc_lp[2]);
            acc_rate[0] = acc_rate[1] = acc_rate[2] = 0.0;
        } else {
            lowpass(&acc_lp[0], &acc_rate[0], a.x, coef->Ad, coef->Bd);
            lowpass(&acc_lp[1], &acc_rate[1], a.y, coef->Ad, coef->Bd);
            lowpass(&acc_lp[2], &acc_rate[2], a.z, coef->Ad, coef->Bd);
        }
        for (int i = 0; i < 9; i++)
            lowpass(&state->r_lp[0][i], &state->r_lp[1][i], R[i], coef->Ad, coef->Bd);
        lowpass(&state->rb_lp[0][0], &state->rb_lp[1][0], rb.x, coef->Ad, coef->Bd);
        lowpass(&state->rb_lp[0][1], &state->rb_lp[1][1], rb.y, coef->Ad, coef->Bd);
        lowpass(&state->rb_lp[0][2], &state->rb_lp[1][2], rb.z, coef->Ad, coef->Bd);
        if (coef->arm_every > 0.0) { /* the lever arm: w and alpha from this sample and the one before */
            double *before = state->arm_gyr, phase = state->arm_phase += 1.0;
            int fit = phase >= coef->arm_every;
            int on = state->arm[0] != 0.0 || state->arm[1] != 0.0 || state->arm[2] != 0.0;
            if (fit || on) {
                double rate = 1.0 / Ts;
                double w[3] = {0.5 * (gyr[0] + before[0]) - b[0], 0.5 * (gyr[1] + before[1]) - b[1],
                               0.5 * (gyr[2] + before[2]) - b[2]};
                double alpha[3] = {(gyr[0] - before[0]) * rate, (gyr[1] - before[1]) * rate,
                                   (gyr[2] - before[2]) * rate};
                if (on)
                    arm_accelerations(w, alpha, state->arm, removed);
                if (fit) {
                    double y[3] = {a.x, a.y, a.z};
                    state->arm_phase = 0.0;
                    arm_fit(state, coef, R, y, w, alpha);
                }
            }
            if (on || phase + 1.0 >= coef->arm_every) /* the sample before the next that needs one */
                before[0] = gyr[0], before[1] = gyr[1], before[2] = gyr[2];
        }
    }
    for (int i = 0; i < 3; i++) {
        double p = P[4 * i] + V;
        P[4 * i] = coef->P0 < p ? coef->P0 : p;
    }
    int rested = state->rest >= coef->rest_time;
    if (resting != NULL)
        *resting = (unsigned char)rested;
    if (rested && allowed) { /* each axis of the gyro sample measures b with variance r */
        for (int i = 0; i < 3; i++) {
            double h[3] = {i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0};
            scalar_update(b, P, h, state->rest_gyr_mean[i], coef->r);
        }
    } else if (V > 0.0 && state->t > coef->settle) {
        motion_update(b, P, old, state->acc_lp[0], state->r_lp[0], state->rb_lp[0], Ts, coef->W, coef->clip);
    }
    for (int i = 0; i < 3; i++) {
        offset[i] = b[i];
        variance[i] = P[4 * i];
    }
    if (acc_out != NULL && (acc_out != acc || removed[0] != 0.0 || removed[1] != 0.0 || removed[2] != 0.0))
        for (int i = 0; i < 3; i++) /* acc read above: acc_out may be acc */
            acc_out[i] = acc[i] - removed[i];
}

void gyro_offset_step(AfGyroOffset *state, const AfGyroOffsetCoef *coef, const double gyr[3], const double acc[3],
                      double offset[3], double variance[3], double acc_out[3])
{
    step(state, coef, gyr, acc, 1, offset, variance, acc_out, NULL);
}

void gyro_offset_run(AfGyroOffset *state, const AfGyroOffsetCoef *coef, size_t n, const double *gyr,
                     const double *acc, const unsigned char *allowed, double *offset, double *variance,
                     double *acc_out, unsigned char *resting)
{
    for (size_t k = 0; k < n; k++)
        step(state, coef, gyr + 3 * k, acc + 3 * k, allowed == NULL || allowed[k], offset + 3 * k, variance + 3 * k,
             acc_out != NULL ? acc_out + 3 * k : NULL, resting != NULL ? resting + k : NULL);
}
