/* gyro_offset.c: Python twin blocks/stages/gyro_offset.py; the same operations in the same order. */
#include "stages/gyro_offset.h"

#include <math.h>

#include "methods/wiener_local.h"
#include "quaternion.h"

/* the state's layout (STATE_NAMES): low-passed gyro 0..2, accelerometer 3..5, time at rest 6, offset b 7..9 */
#define T 10       /* time since the start (s) */
#define QUAT 11    /* sensor -> gyro frame, 4 entries */
#define ACC_LP 15  /* Butterworth rows of the accelerometer in the gyro frame, 2 x 3 */
#define R_LP 21    /* Butterworth rows of R, 2 x 9 */
#define RB_LP 39   /* Butterworth rows of R.b, 2 x 3 */
#define COV 45     /* covariance of the offset estimate, 3 x 3 */
#define SHORT 54   /* gyro and accelerometer through the short low-pass, 6 entries */
#define OBSERVED 0.5    /* the least share of an offset's effect H must keep in a direction to update it */
#define CLIP_SIGMAS 4.0 /* innovations clipped at this many sigma_init */
#define SETTLE_TAUS 3.0 /* no update before this many tau_acc (the low-pass forgetting its start) */

void gyro_offset_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[GYRO_OFFSET_COEF_SIZE])
{
    double tau_motion = params[AF_P_tau_motion], s2 = params[AF_P_sigma_motion] * params[AF_P_sigma_motion];
    double V = tau_motion > 0 ? s2 * Ts / tau_motion : 0.0;
    double delta_n = params[AF_P_delta_n];
    double noise_floor = REST_NOISE_SIGMAS * delta_n / sqrt(4 * params[AF_P_tau_short]);
    coef[0] = Ts;
    coef[1] = 1.0 - exp(-Ts / params[AF_P_tau_lp]);
    coef[2] = delta_n * delta_n / (2.0 * Ts);
    coef[3] = noise_floor > params[AF_P_rest_gyr] ? noise_floor : params[AF_P_rest_gyr];
    coef[4] = params[AF_P_rest_gyr_abs];
    coef[5] = params[AF_P_rest_acc];
    coef[6] = params[AF_P_rest_time];
    coef[7] = sqrt(2.0) / params[AF_P_tau_acc] * Ts;
    coef[8] = params[AF_P_sigma_init] * params[AF_P_sigma_init];
    coef[9] = V;
    coef[10] = V > 0 ? s2 * s2 / V + s2 : 0.0;
    coef[11] = 1.0 - exp(-Ts / params[AF_P_tau_short]);
}

void gyro_offset_initial_state(const double coef[GYRO_OFFSET_COEF_SIZE], const double gyr0[3], const double acc0[3],
                               double state[GYRO_OFFSET_STATE_SIZE])
{
    for (int i = 0; i < GYRO_OFFSET_STATE_SIZE; i++)
        state[i] = 0.0;
    for (int i = 0; i < 3; i++) {
        state[i] = state[SHORT + i] = gyr0[i];
        state[3 + i] = state[SHORT + 3 + i] = acc0[i];
        state[R_LP + 4 * i] = 1.0;   /* LP(R) settled on I */
        state[COV + 4 * i] = coef[8]; /* P0 on the diagonal */
    }
    state[QUAT] = 1.0;
}

/* lowpass_step: column j of the Butterworth's two state rows (rows, each of width columns) after the input x */
static void lowpass_step(double *rows, int width, int j, double x, const double Ad[4], const double Bd[2])
{
    double x0 = rows[j], x1 = rows[width + j];
    rows[j] = Ad[0] * x0 + Ad[1] * x1 + Bd[0] * x;
    rows[width + j] = Ad[2] * x0 + Ad[3] * x1 + Bd[1] * x;
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
static void scalar_update(double b[3], double P[9], const double h[3], double z, double w)
{
    double Ph[3];
    mat_vec(P, h, Ph);
    double inv_s = 1.0 / (dot(h, Ph) + w);
    double innovation = (z - dot(h, b)) * inv_s;
    for (int i = 0; i < 3; i++) {
        b[i] += Ph[i] * innovation;
        for (int j = 0; j < 3; j++)
            P[3 * i + j] -= Ph[i] * Ph[j] * inv_s;
    }
}

/* plane_basis: two orthonormal vectors e1, e2 across the unit vector n */
static void plane_basis(const double n[3], double e1[3], double e2[3])
{
    double e[3];
    /* the axis least along n, crossed with n */
    if (fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2])) {
        e[0] = 0.0, e[1] = n[2], e[2] = -n[1];
    } else if (fabs(n[1]) <= fabs(n[2])) {
        e[0] = -n[2], e[1] = 0.0, e[2] = n[0];
    } else {
        e[0] = n[1], e[1] = -n[0], e[2] = 0.0;
    }
    double norm = sqrt(dot(e, e));
    for (int i = 0; i < 3; i++)
        e1[i] = e[i] / norm;
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

/* motion_update: Kalman update of the offset b (P its covariance) from the turn of the low-passed
 * accelerometer from old to new (gyro frame); r_lp, rb_lp: LP(R) (row-major) and LP(R.b). Only
 * the directions across gravity that H = Pi.LP(R) keeps at least OBSERVED of are used, each as a
 * scalar measurement with variance W (see the Python twin). */
static void motion_update(double b[3], double P[9], const double old[3], const double new[3], const double r_lp[9],
                          const double rb_lp[3], double Ts, double W, double clip)
{
    double n2 = dot(new, new);
    if (n2 == 0.0)
        return;
    double norm = sqrt(n2);
    double n[3] = {new[0] / norm, new[1] / norm, new[2] / norm};
    double e1[3], e2[3];
    plane_basis(n, e1, e2);
    double b0[3] = {b[0], b[1], b[2]};
    double s = 1.0 / (n2 * Ts);
    double turn[3] = {(old[1] * new[2] - old[2] * new[1]) * s, (old[2] * new[0] - old[0] * new[2]) * s,
                      (old[0] * new[1] - old[1] * new[0]) * s};
    double Lb[3];
    mat_vec(r_lp, b, Lb);
    double d[3] = {rb_lp[0] - Lb[0], rb_lp[1] - Lb[1], rb_lp[2] - Lb[2]}; /* LP(R.b) - LP(R).b, across gravity below */
    double along = dot(d, n);
    double e[3];
    for (int i = 0; i < 3; i++)
        e[i] = clipped(turn[i] + d[i] - along * n[i], clip);
    /* M = (e1, e2)^T.LP(R), 2 x 3; the eigenvectors of M.M^T are H's left singular directions */
    double m1[3], m2[3];
    mat_t_vec(r_lp, e1, m1);
    mat_t_vec(r_lp, e2, m2);
    double p11 = dot(m1, m1), p12 = dot(m1, m2), p22 = dot(m2, m2);
    double half = 0.5 * (p11 - p22), mean = 0.5 * (p11 + p22);
    double radius = sqrt(half * half + p12 * p12);
    /* the eigenvector of the larger eigenvalue mean + radius, in its well-conditioned form */
    double c, sn;
    if (half >= 0.0)
        c = half + radius, sn = p12;
    else
        c = p12, sn = radius - half;
    double length = sqrt(c * c + sn * sn);
    if (length > 0.0)
        c = c / length, sn = sn / length;
    else
        c = 1.0, sn = 0.0;
    for (int a = 0; a < 2; a++) {
        if (a == 1) {
            double c0 = c;
            c = -sn, sn = c0;
        }
        if (mean + (a == 0 ? radius : -radius) < OBSERVED * OBSERVED)
            continue;
        double u[3], h[3];
        for (int i = 0; i < 3; i++) {
            u[i] = c * e1[i] + sn * e2[i];
            h[i] = c * m1[i] + sn * m2[i]; /* H^T.u */
        }
        /* u.e measures h.b at the b the innovation was taken at; later directions see the update */
        double z = dot(u, e) + dot(h, b0);
        scalar_update(b, P, h, z, W);
    }
}

void gyro_offset_step(double state[GYRO_OFFSET_STATE_SIZE], const double coef[GYRO_OFFSET_COEF_SIZE],
                      const double gyr[3], const double acc[3], double offset[3], double variance[3])
{
    double Ts = coef[0], a_lp = coef[1], r = coef[2], rest_gyr = coef[3], rest_gyr_abs = coef[4];
    double rest_acc = coef[5], rest_time = coef[6], wt = coef[7], P0 = coef[8], V = coef[9], W = coef[10];
    double a_short = coef[11];
    double start_mean = sqrt(2.0) * Ts / wt; /* tau_acc */
    double settle = SETTLE_TAUS * start_mean;
    double clip = CLIP_SIGMAS * sqrt(P0);
    double Ad[4], Bd[2];
    butterworth_zoh(wt, Ad, Bd);
    double *b = state + 7, *acc_lp = state + ACC_LP, *r_lp = state + R_LP, *rb_lp = state + RB_LP, *P = state + COV;
    double dg2 = 0.0, da2 = 0.0, g2 = 0.0;
    for (int i = 0; i < 3; i++) {
        state[i] += a_lp * (gyr[i] - state[i]);
        state[3 + i] += a_lp * (acc[i] - state[3 + i]);
        state[SHORT + i] += a_short * (gyr[i] - state[SHORT + i]);
        state[SHORT + 3 + i] += a_short * (acc[i] - state[SHORT + 3 + i]);
        double dg = state[SHORT + i] - state[i], da = state[SHORT + 3 + i] - state[3 + i];
        dg2 += dg * dg;
        da2 += da * da;
        g2 += state[i] * state[i];
    }
    int still = dg2 < rest_gyr * rest_gyr && da2 < rest_acc * rest_acc && g2 < rest_gyr_abs * rest_gyr_abs;
    state[6] = still ? state[6] + Ts : 0.0;
    double old[3] = {acc_lp[0], acc_lp[1], acc_lp[2]};
    if (V > 0.0) { /* tracking while moving: the gyro frame and its low-passes */
        Quat q = quat_normalized(quat_multiply( /* turned by the corrected gyro */
            quat_load(state + QUAT),
            rotvec_quat((gyr[0] - b[0]) * Ts, (gyr[1] - b[1]) * Ts, (gyr[2] - b[2]) * Ts)));
        quat_store(q, state + QUAT);
        state[T] += Ts;
        /* the accelerometer, R.b and R (row-major) low-passed */
        double R[9], a[3], rb[3];
        quat_matrix(q, R);
        mat_vec(R, acc, a);
        mat_vec(R, b, rb);
        int mean = state[T] <= start_mean;
        for (int i = 0; i < 3; i++) {
            if (mean) { /* the running mean, derivative row at rest */
                acc_lp[i] += Ts / state[T] * (a[i] - acc_lp[i]);
                acc_lp[3 + i] = 0.0;
            } else {
                lowpass_step(acc_lp, 3, i, a[i], Ad, Bd);
            }
            lowpass_step(rb_lp, 3, i, rb[i], Ad, Bd);
        }
        for (int i = 0; i < 9; i++)
            lowpass_step(r_lp, 9, i, R[i], Ad, Bd);
    }
    for (int i = 0; i < 3; i++) {
        double p = P[4 * i] + V;
        P[4 * i] = P0 < p ? P0 : p;
    }
    if (state[6] >= rest_time) { /* each axis of the gyro sample measures b with variance r */
        for (int i = 0; i < 3; i++) {
            double h[3] = {i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0};
            scalar_update(b, P, h, gyr[i], r);
        }
    } else if (V > 0.0 && state[T] > settle) {
        motion_update(b, P, old, acc_lp, r_lp, rb_lp, Ts, W, clip);
    }
    for (int i = 0; i < 3; i++) {
        offset[i] = b[i];
        variance[i] = P[4 * i];
    }
}
