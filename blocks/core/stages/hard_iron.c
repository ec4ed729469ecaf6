/* hard_iron.c: Python twin blocks/stages/hard_iron.py (its online part: coefficients,
 * hard_iron_step and what it calls); the same operations in the same order. */
#include "stages/hard_iron.h"

#include <math.h>

/* the state's layout (STATE_NAMES) */
#define SUMS 0         /* 15 running sums: 1, m, m.m^T, m.|m|^2, |m|^2, |m|^4 */
#define OFFSET HARD_IRON_STATE_OFFSET /* the offset in use, 3 entries */
#define FIT_STEPS 18   /* steps the fit has held steady */
#define RAW_STEPS 19   /* steps the field as it is has held steady */
#define RECENT_FIT 20  /* the latest samples' mean square distance from the fitted sphere, relative to its radius */
#define RECENT_RAW 21  /* the same for the sphere about 0 */
#define AGE 22         /* steps since the sums started afresh */
#define EXPLAINED 0.5  /* the fit's residual must be below this share of the field's own */

static const double PI = 3.14159265358979323846;

void hard_iron_coefficients(const double params[AF_N_PARAMS], double Ts, double coef[HARD_IRON_COEF_SIZE])
{
    double cal_steps = params[AF_P_mag_cal_time] / Ts, recent_steps = params[AF_P_mag_cal_recent] / Ts;
    coef[0] = cal_steps;
    coef[1] = params[AF_P_mag_cal_spread];
    coef[2] = params[AF_P_mag_cal_tol];
    coef[3] = recent_steps;
    coef[4] = cal_steps > 0.0 ? 1.0 - exp(-1.0 / cal_steps) : 0.0;
    coef[5] = 1.0 - exp(-1.0 / recent_steps);
}

double pull(double gap, double rate, double one_step)
{
    return gap == 1.0 ? one_step : 1.0 - exp(-gap * rate);
}

/* accumulate: the running sums s after the field sample m, the old sums scaled by forget */
static void accumulate(double s[15], Vec3 m, double forget)
{
    double n2 = m.x * m.x + m.y * m.y + m.z * m.z;
    double terms[15] = {1.0, m.x, m.y, m.z, m.x * m.x, m.x * m.y, m.x * m.z, m.y * m.y, m.y * m.z,
                        m.z * m.z, m.x * n2, m.y * n2, m.z * n2, n2, n2 * n2};
    for (int i = 0; i < 15; i++)
        s[i] = forget * s[i] + terms[i];
}

/* covariance: the field's mean mu and covariance c (xx, xy, xz, yy, yz, zz) from the sums s */
static void covariance(const double s[15], double mu[3], double c[6])
{
    double w = 1.0 / s[0];
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

/* spread: the s.d. of the field across its smallest axis, the square root of the covariance's
 * least eigenvalue in the closed form of a symmetric 3 x 3 matrix */
static double spread(const double s[15])
{
    double mu[3], cov[6];
    covariance(s, mu, cov);
    double xx = cov[0], xy = cov[1], xz = cov[2], yy = cov[3], yz = cov[4], zz = cov[5];
    double mean = (xx + yy + zz) / 3.0;
    double off2 = xy * xy + xz * xz + yz * yz;
    double p = sqrt((square(xx - mean) + square(yy - mean) + square(zz - mean) + 2.0 * off2) / 6.0);
    if (p == 0.0)
        return sqrt(at_least_0(mean));
    double a = (xx - mean) / p, d = (yy - mean) / p, f = (zz - mean) / p;
    double b = xy / p, c = xz / p, e = yz / p;
    double half_det = 0.5 * (a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d));
    double bounded = half_det < -1.0 ? -1.0 : half_det;
    double angle = acos(1.0 < bounded ? 1.0 : bounded) / 3.0;
    return sqrt(at_least_0(mean + 2.0 * p * cos(angle + 2.0 * PI / 3.0)));
}

/* Fit: the algebraic sphere fit of the sums, and the sphere about 0 (the field as it is) */
typedef struct {
    Vec3 b;              /* the fitted centre */
    double radius;       /* 0: no fit */
    double distance;     /* rms distance from the fitted sphere */
    double raw_radius;   /* the same for the sphere about 0 */
    double raw_distance;
} Fit;

/* fit: with c eliminated, 2.C.b = E[m.|m|^2] - mu.E|m|^2 (C the field's covariance, mu its mean),
 * c = E|m|^2 - 2 mu.b; all in the field's unit */
static Fit fit(const double s[15])
{
    double mu[3], cov[6];
    covariance(s, mu, cov);
    double xx = cov[0], xy = cov[1], xz = cov[2], yy = cov[3], yz = cov[4], zz = cov[5];
    double n2 = s[13] / s[0], n4 = s[14] / s[0];
    double raw_radius = sqrt(n2);
    double raw_distance = sqrt(at_least_0(n4 - n2 * n2)) / (2.0 * raw_radius);
    Fit none = {{0.0, 0.0, 0.0}, 0.0, 0.0, raw_radius, raw_distance};
    /* the adjugate of C and its determinant */
    double a0 = yy * zz - yz * yz, a1 = xz * yz - xy * zz, a2 = xy * yz - xz * yy;
    double a4 = xx * zz - xz * xz, a5 = xy * xz - xx * yz, a8 = xx * yy - xy * xy;
    double det = xx * a0 + xy * a1 + xz * a2;
    if (fabs(det) < 1e-12 * pow(n2, 3)) /* too few directions for a sphere */
        return none;
    double w = 0.5 / s[0]; /* the right-hand side halved, over det */
    double v0 = (s[10] * w - 0.5 * mu[0] * n2) / det;
    double v1 = (s[11] * w - 0.5 * mu[1] * n2) / det;
    double v2 = (s[12] * w - 0.5 * mu[2] * n2) / det;
    Vec3 b = {a0 * v0 + a1 * v1 + a2 * v2, a1 * v0 + a4 * v1 + a5 * v2, a2 * v0 + a5 * v1 + a8 * v2};
    double c = n2 - 2.0 * (mu[0] * b.x + mu[1] * b.y + mu[2] * b.z);
    double r2 = c + b.x * b.x + b.y * b.y + b.z * b.z;
    if (r2 <= 0.0)
        return none;
    double radius = sqrt(r2);
    /* mean of (|m|^2 - 2m.b - c)^2 at the solution: E|m|^4 - 2b.E[m.|m|^2] - c.E|m|^2 */
    double residual2 = n4 - 4.0 * w * (b.x * s[10] + b.y * s[11] + b.z * s[12]) - c * n2;
    return (Fit){b, radius, sqrt(at_least_0(residual2)) / (2.0 * radius), raw_radius, raw_distance};
}

/* recent: low-pass (weight a) of the squared distance of m from the sphere (centre, radius),
 * relative to the radius, into state[index]; its value */
static double recent(double *state, int index, Vec3 m, Vec3 centre, double radius, double a)
{
    if (radius > 0.0) {
        double dx = m.x - centre.x, dy = m.y - centre.y, dz = m.z - centre.z;
        double e = sqrt(dx * dx + dy * dy + dz * dz) / radius - 1.0;
        state[index] += a * (e * e - state[index]);
    }
    return state[index];
}

/* less_offset: the field sample m less the offset in use */
static Vec3 less_offset(Vec3 m, const double *state)
{
    return (Vec3){m.x - state[OFFSET], m.y - state[OFFSET + 1], m.z - state[OFFSET + 2]};
}

Vec3 hard_iron_step(double state[HARD_IRON_STATE_SIZE], const double coef[HARD_IRON_COEF_SIZE], Vec3 m, double gap,
                    double norm_tol, double steady_steps, int *changed)
{
    double cal_steps = coef[0], spread_min = coef[1], tol = coef[2], recent_steps = coef[3];
    *changed = 0;
    if (cal_steps <= 0.0)
        return m;
    accumulate(state + SUMS, m, 1.0 - pull(gap, 1.0 / cal_steps, coef[4]));
    state[AGE] += gap;
    Fit f = fit(state + SUMS);
    double a = pull(gap, 1.0 / recent_steps, coef[5]);
    double recent_fit = recent(state, RECENT_FIT, m, f.b, f.radius, a);
    double recent_raw = recent(state, RECENT_RAW, m, (Vec3){0.0, 0.0, 0.0}, f.raw_radius, a);
    int fits = f.radius > 0.0 && f.distance < tol * f.radius;
    int raw_fits = f.raw_distance < tol * f.raw_radius;
    double offset = sqrt(f.b.x * f.b.x + f.b.y * f.b.y + f.b.z * f.b.z);
    int better = fits && f.distance < EXPLAINED * f.raw_distance; /* the sphere about b, not about 0, is the window's */
    int explained = better && offset > norm_tol * f.radius;
    int left_fit = fits && recent_fit > tol * tol;
    /* the sphere about 0 needs no spread: samples off the field's own norm, even at rest, show it has changed */
    int left_raw = raw_fits && !better && recent_raw > tol * tol;
    int was_used = state[OFFSET] != 0.0 || state[OFFSET + 1] != 0.0 || state[OFFSET + 2] != 0.0;
    int drop = raw_fits && was_used; /* only an offset in use can be dropped */
    int unfit = !(fits || raw_fits); /* the window fits neither sphere: it holds a change, or a field that varies */
    double covered = spread_min * (fits ? f.radius : f.raw_radius); /* the least spread that tells a sphere */
    if ((left_fit || explained || drop || unfit) && spread(state + SUMS) < covered)
        left_fit = explained = drop = unfit = 0; /* too few directions to tell a sphere */
    if (state[AGE] >= steady_steps && (left_fit || left_raw || unfit)) {
        /* the field has changed (the latest samples have left the window's sphere, or a window covering
         * every direction fits none): the fit starts afresh */
        accumulate(state + SUMS, m, 0.0);
        state[FIT_STEPS] = state[RAW_STEPS] = state[RECENT_FIT] = state[RECENT_RAW] = state[AGE] = 0.0;
        return less_offset(m, state);
    }
    if (explained) {
        state[FIT_STEPS] += gap;
        state[RAW_STEPS] = 0.0;
        if (state[FIT_STEPS] >= steady_steps) {
            state[OFFSET] = f.b.x, state[OFFSET + 1] = f.b.y, state[OFFSET + 2] = f.b.z;
            *changed = !was_used;
        }
    } else if (drop) {
        state[RAW_STEPS] += gap;
        state[FIT_STEPS] = 0.0;
        if (state[RAW_STEPS] >= steady_steps) {
            state[OFFSET] = state[OFFSET + 1] = state[OFFSET + 2] = 0.0;
            *changed = was_used;
        }
    } else {
        state[FIT_STEPS] = 0.0;
        state[RAW_STEPS] = 0.0;
    }
    return less_offset(m, state);
}
