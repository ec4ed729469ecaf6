/* hard_iron.c: the online hard-iron fit (documented in blocks/stages/hard_iron.py). */
#include "stages/hard_iron.h"

#include <math.h>

#define EXPLAINED 0.5 /* the fit's residual must be below this share of the field's own */

#define STATE_FIELD(name, dims) AF_FIELD(AfHardIron, name)
const AfField HARD_IRON_STATE_FIELDS[] = {HARD_IRON_FIELDS(STATE_FIELD)};
const size_t HARD_IRON_N_FIELDS = sizeof HARD_IRON_STATE_FIELDS / sizeof HARD_IRON_STATE_FIELDS[0];

void hard_iron_coefficients(const double params[AF_N_PARAMS], double Ts, AfHardIronCoef *coef)
{
    double cal_steps = params[AF_P_mag_cal_time] / Ts, recent_steps = params[AF_P_mag_cal_recent] / Ts;
    coef->cal_steps = cal_steps;
    coef->spread_min = params[AF_P_mag_cal_spread];
    coef->tol = params[AF_P_mag_cal_tol];
    coef->a_cal = cal_steps > 0.0 ? 1.0 - exp(-1.0 / cal_steps) : 0.0;
    coef->a_recent = 1.0 - exp(-1.0 / recent_steps);
    coef->rate_cal = cal_steps > 0.0 ? 1.0 / cal_steps : 0.0;
    coef->rate_recent = 1.0 / recent_steps;
}

/* accumulate: the running sums s after the field sample m, the old sums scaled by forget */
static inline void accumulate(double s[15], Vec3 m, double forget)
{
    double n2 = m.x * m.x + m.y * m.y + m.z * m.z;
    /* term by term: the terms in an array go through the stack, stored one at a time and read two at a time */
    s[0] = forget * s[0] + 1.0;
    s[1] = forget * s[1] + m.x;
    s[2] = forget * s[2] + m.y;
    s[3] = forget * s[3] + m.z;
    s[4] = forget * s[4] + m.x * m.x;
    s[5] = forget * s[5] + m.x * m.y;
    s[6] = forget * s[6] + m.x * m.z;
    s[7] = forget * s[7] + m.y * m.y;
    s[8] = forget * s[8] + m.y * m.z;
    s[9] = forget * s[9] + m.z * m.z;
    s[10] = forget * s[10] + m.x * n2;
    s[11] = forget * s[11] + m.y * n2;
    s[12] = forget * s[12] + m.z * n2;
    s[13] = forget * s[13] + n2;
    s[14] = forget * s[14] + n2 * n2;
}

/* covariance: the field's mean mu and covariance c (xx, xy, xz, yy, yz, zz) from the sums s, w = 1/s[0] */
static void covariance(const double s[15], double w, double mu[3], double c[6])
{
    double mx = s[1] * w, my = s[2] * w, mz = s[3] * w;
    mu[0] = mx, mu[1] = my, mu[2] = mz;
    c[0] = s[4] * w - mx * mx;
    c[1] = s[5] * w - mx * my;
    c[2] = s[6] * w - mx * mz;
    c[3] = s[7] * w - my * my;
    c[4] = s[8] * w - my * mz;
    c[5] = s[9] * w - mz * mz;
}

static double square(double x)
{
    return x * x;
}

static double at_least_0(double x)
{
    return 0.0 > x ? 0.0 : x;
}

/* spread2: the variance of the field across its smallest axis, the covariance's least eigenvalue
 * (0 at least) in the closed form of a symmetric 3 x 3 matrix */
static double spread2(const double s[15])
{
    double mu[3], cov[6];
    covariance(s, 1.0 / s[0], mu, cov);
    double xx = cov[0], xy = cov[1], xz = cov[2], yy = cov[3], yz = cov[4], zz = cov[5];
    double mean = (xx + yy + zz) / 3.0;
    double off2 = xy * xy + xz * xz + yz * yz;
    double p = sqrt((square(xx - mean) + square(yy - mean) + square(zz - mean) + 2.0 * off2) / 6.0);
    if (p == 0.0)
        return at_least_0(mean);
    double a = (xx - mean) / p, d = (yy - mean) / p, f = (zz - mean) / p;
    double b = xy / p, c = xz / p, e = yz / p;
    double half_det = 0.5 * (a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d));
    double bounded = half_det < -1.0 ? -1.0 : half_det;
    double angle = acos(1.0 < bounded ? 1.0 : bounded) / 3.0;
    return at_least_0(mean + 2.0 * p * cos(angle + 2.0 * AF_PI / 3.0));
}

/* Fit: the algebraic sphere fit of the sums, and the sphere about 0 (the field as it is), in
 * squares: a sphere of radius r whose algebraic residual |m|^2 - 2m.b - c has the mean square e2
 * lies at the rms distance sqrt(e2)/(2r) from the samples */
typedef struct {
    Vec3 b;      /* the fitted centre */
    double r2;   /* its radius squared; 0: no fit */
    double e2;   /* the mean square residual */
    double n2;   /* the sphere about 0's radius squared, E|m|^2 */
    double raw2; /* its mean square residual, E|m|^4 - (E|m|^2)^2 */
} Fit;

/* fit: with c eliminated, 2.C.b = E[m.|m|^2] - mu.E|m|^2 (C the field's covariance, mu its mean),
 * c = E|m|^2 - 2 mu.b; all in the field's unit */
static Fit fit(const double s[15])
{
    double mu[3], cov[6], inv_count = 1.0 / s[0];
    covariance(s, inv_count, mu, cov);
    double xx = cov[0], xy = cov[1], xz = cov[2], yy = cov[3], yz = cov[4], zz = cov[5];
    double n2 = s[13] * inv_count, n4 = s[14] * inv_count;
    Fit none = {{0.0, 0.0, 0.0}, 0.0, 0.0, n2, at_least_0(n4 - n2 * n2)};
    /* the adjugate of C and its determinant */
    double a0 = yy * zz - yz * yz, a1 = xz * yz - xy * zz, a2 = xy * yz - xz * yy;
    double a4 = xx * zz - xz * xz, a5 = xy * xz - xx * yz, a8 = xx * yy - xy * xy;
    double det = xx * a0 + xy * a1 + xz * a2;
    if (fabs(det) < 1e-12 * (n2 * n2 * n2)) /* too few directions for a sphere */
        return none;
    double w = 0.5 * inv_count, inv_det = 1.0 / det; /* the right-hand side halved, over det */
    double v0 = (s[10] * w - 0.5 * mu[0] * n2) * inv_det;
    double v1 = (s[11] * w - 0.5 * mu[1] * n2) * inv_det;
    double v2 = (s[12] * w - 0.5 * mu[2] * n2) * inv_det;
    Vec3 b = {a0 * v0 + a1 * v1 + a2 * v2, a1 * v0 + a4 * v1 + a5 * v2, a2 * v0 + a5 * v1 + a8 * v2};
    double c = n2 - 2.0 * (mu[0] * b.x + mu[1] * b.y + mu[2] * b.z);
    double r2 = c + b.x * b.x + b.y * b.y + b.z * b.z;
    if (r2 <= 0.0)
        return none;
    /* mean of (|m|^2 - 2m.b - c)^2 at the solution: E|m|^4 - 2b.E[m.|m|^2] - c.E|m|^2 */
    double e2 = n4 - 4.0 * w * (b.x * s[10] + b.y * s[11] + b.z * s[12]) - c * n2;
    return (Fit){b, r2, at_least_0(e2), none.n2, none.raw2};
}

/* recent: low-pass (weight a) of the squared distance of m from the sphere (centre, radius squared
 * r2 > 0), relative to the radius, into *mean_square; its value */
static double recent(double *mean_square, Vec3 m, Vec3 centre, double r2, double a)
{
    if (r2 > 0.0) {
        double dx = m.x - centre.x, dy = m.y - centre.y, dz = m.z - centre.z;
        double e = sqrt((dx * dx + dy * dy + dz * dz) / r2) - 1.0;
        *mean_square += a * (e * e - *mean_square);
    }
    return *mean_square;
}

int hard_iron_step(AfHardIron *state, const AfHardIronCoef *coef, double mx, double my, double mz, double gap,
                   double norm_tol, double steady_steps)
{
    double spread_min = coef->spread_min, tol = coef->tol;
    Vec3 m = {mx, my, mz};
    if (coef->cal_steps <= 0.0)
        return 0;
    accumulate(state->sums, m, 1.0 - pull(gap, coef->rate_cal, coef->a_cal));
    state->age += gap;
    Fit f = fit(state->sums);
    double a = pull(gap, coef->rate_recent, coef->a_recent);
    double recent_fit = recent(&state->recent_fit, m, f.b, f.r2, a);
    double recent_raw = recent(&state->recent_raw, m, (Vec3){0.0, 0.0, 0.0}, f.n2, a);
    /* the distances d = sqrt(e2)/(2r) compared in squares: d < tol.r as e2 < 4 tol^2 r2^2 */
    double tol4 = 4.0 * tol * tol;
    int fits = f.r2 > 0.0 && f.e2 < tol4 * f.r2 * f.r2;
    int raw_fits = f.raw2 < tol4 * f.n2 * f.n2;
    double offset2 = f.b.x * f.b.x + f.b.y * f.b.y + f.b.z * f.b.z;
    /* the sphere about b, not about 0, is the window's: its distance below EXPLAINED times the other's */
    int better = fits && f.e2 * f.n2 < EXPLAINED * EXPLAINED * f.raw2 * f.r2;
    int explained = better && offset2 > norm_tol * norm_tol * f.r2;
    int left_fit = fits && recent_fit > tol * tol;
    /* the sphere about 0 needs no spread: samples off the field's own norm, even at rest, show it has changed */
    int left_raw = raw_fits && !better && recent_raw > tol * tol;
    int was_used = state->offset[0] != 0.0 || state->offset[1] != 0.0 || state->offset[2] != 0.0;
    int drop = raw_fits && was_used; /* only an offset in use can be dropped */
    int unfit = !(fits || raw_fits); /* the window fits neither sphere: it holds a change, or a field that varies */
    double covered2 = spread_min * spread_min * (fits ? f.r2 : f.n2); /* the least spread that tells a sphere, ^2 */
    if ((left_fit || explained || drop || unfit) && spread2(state->sums) < covered2)
        left_fit = explained = drop = unfit = 0; /* too few directions to tell a sphere */
    if (state->age >= steady_steps && (left_fit || left_raw || unfit)) {
        /* the field has changed (the latest samples have left the window's sphere, or a window covering
         * every direction fits none): the fit starts afresh */
        accumulate(state->sums, m, 0.0);
        state->fit_steps = state->raw_steps = state->recent_fit = state->recent_raw = state->age = 0.0;
        return 0;
    }
    int changed = 0;
    if (explained) {
        state->fit_steps += gap;
        state->raw_steps = 0.0;
        if (state->fit_steps >= steady_steps) {
            state->offset[0] = f.b.x, state->offset[1] = f.b.y, state->offset[2] = f.b.z;
            changed = !was_used;
        }
    } else if (drop) {
        state->raw_steps += gap;
        state->fit_steps = 0.0;
        if (state->raw_steps >= steady_steps) {
            state->offset[0] = state->offset[1] = state->offset[2] = 0.0;
            changed = was_used;
        }
    } else {
        state->fit_steps = 0.0;
        state->raw_steps = 0.0;
    }
    return changed;
}
