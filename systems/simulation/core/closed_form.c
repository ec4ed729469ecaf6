/* closed_form.c: the closed-form profiles, in quaternion algebra: the products in the order of
 * scipy's Rotation compositions that the profiles were written with, so the quaternions carry
 * their sign. */
#include "closed_form.h"

#include <math.h>
#include <string.h>

#include "quaternion.h"

#define PI 3.141592653589793
#define STEP_LEVELS 10 /* STEP_SIZES_DEG, each followed by 0 */
static const double STEP_SIZES_DEG[STEP_LEVELS / 2] = {5.0, 10.0, 20.0, 45.0, 90.0};

/* ROBOT_ARM's moves: about the body axis (0 x, 1 y, 2 z) by a share of angle_deg; they compose to the identity */
#define ROBOT_MOVES 6
static const struct {
    int axis;
    double share;
} ROBOT_MOVE[ROBOT_MOVES] = {{2, 1.0}, {0, 0.5}, {1, -0.5}, {1, 0.5}, {0, -0.5}, {2, -1.0}};

const char *const CLOSED_FORM_NAMES[N_CLOSED_FORMS] = {
    "lever_arm", "incline", "coning", "sine_rotation", "step_rotation", "linear_motion", "offset_rotation",
    "phone_flat", "running", "robot_arm",
};

static double radians(double degrees) { return degrees * (PI / 180.0); }

/* the rotation about a coordinate axis (0 x, 1 y, 2 z) by angle (rad) */
static Quat rot(int axis, double angle) {
    return rotvec_quat(axis == 0 ? angle : 0.0, axis == 1 ? angle : 0.0, axis == 2 ? angle : 0.0);
}

/* Rotation.from_euler("xy", [a, b], degrees=True): about the fixed x, then the fixed y */
static Quat extrinsic_xy(double a_deg, double b_deg) {
    return quat_multiply(rot(1, radians(b_deg)), rot(0, radians(a_deg)));
}

/* Rotation.from_euler("XYZ", [a, b, c], degrees=True): about x, then the new y, then the new z */
static Quat intrinsic_xyz(double a_deg, double b_deg, double c_deg) {
    return quat_multiply(quat_multiply(rot(0, radians(a_deg)), rot(1, radians(b_deg))), rot(2, radians(c_deg)));
}

/* step_rotation's level i (rad; i a whole number of any sign): STEP_SIZES_DEG, each followed by 0,
 * repeated; NaN where i is not finite */
static double step_level(double i) {
    double n = fmod(i, STEP_LEVELS);
    if (n < 0.0) n += STEP_LEVELS;
    if (!(n >= 0.0 && n < STEP_LEVELS)) return NAN;
    int level = (int)n;
    return level % 2 ? 0.0 : radians(STEP_SIZES_DEG[level / 2]);
}

/* step_rotation's pitch (rad) at t */
static double step_pitch(double hold, double ramp, double t) {
    double i = floor(t / hold);
    double into = t - i * hold;
    double now = step_level(i), before = step_level(i - 1.0);
    double blend = into < ramp ? 0.5 - 0.5 * cos(PI * fmin(fmax(into / ramp, 0.0), 1.0)) : 1.0;
    return t < hold ? now * blend : before + (now - before) * blend;
}

/* Rotation.from_euler("ZYX", [yaw, pitch, roll]) (rad): about z, then the new y, then the new x */
static Quat yaw_pitch_roll(double yaw, double pitch, double roll) {
    return quat_multiply(quat_multiply(rot(2, yaw), rot(1, pitch)), rot(0, roll));
}

/* ROBOT_ARM at t: the move j under way (or the last one, resting after it), its share s done and ds/dt (1/s) */
typedef struct {
    int j;
    double s, rate;
} RobotMove;

static RobotMove robot_move(const double *p, double t) {
    double move = p[1], period = p[1] + p[2];
    double i = floor(t / period), n = fmod(i, ROBOT_MOVES);
    if (n < 0.0) n += ROBOT_MOVES;
    double tau = fmin(fmax((t - i * period) / move, 0.0), 1.0);
    RobotMove at = {isfinite(n) ? (int)n : 0, tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau)),
                    30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / move};
    if (!(n >= 0.0 && n < ROBOT_MOVES)) at.s = at.rate = NAN; /* t not finite */
    return at;
}

static Quat robot_orientation(const double *p, double t) {
    RobotMove at = robot_move(p, t);
    Quat q = {1.0, 0.0, 0.0, 0.0};
    for (int j = 0; j < at.j; j++) q = quat_multiply(q, rot(ROBOT_MOVE[j].axis, radians(p[0]) * ROBOT_MOVE[j].share));
    return quat_multiply(q, rot(ROBOT_MOVE[at.j].axis, radians(p[0]) * ROBOT_MOVE[at.j].share * at.s));
}

/* the body rate (rad/s) at t of a profile with a lever arm */
static Vec3 body_rate(const ClosedForm *m, double t) {
    RobotMove at = robot_move(m->p, t);
    double w = radians(m->p[0]) * ROBOT_MOVE[at.j].share * at.rate;
    int axis = ROBOT_MOVE[at.j].axis;
    return (Vec3){axis == 0 ? w : 0.0, axis == 1 ? w : 0.0, axis == 2 ? w : 0.0};
}

/* the lever arm (m, body frame) of a profile that takes one, else NULL */
static const double *lever(const ClosedForm *m) { return m->profile == ROBOT_ARM ? m->p + 3 : NULL; }

static Quat orientation(const ClosedForm *m, double t) {
    const double *p = m->p;
    switch (m->profile) {
    case LEVER_ARM: return quat_multiply(rot(2, p[0] * t), extrinsic_xy(20.0, -10.0));
    case INCLINE: return quat_normalized(rot(1, radians(-p[0])));
    case CONING: return quat_multiply(quat_multiply(rot(2, p[1] * t), rot(0, p[0])), rot(2, -p[1] * t));
    case SINE_ROTATION:
        return quat_multiply(rot(1, radians(p[0]) * sin(2 * PI * p[1] * t)), rot(0, radians(p[2])));
    case STEP_ROTATION: return rot(1, step_pitch(p[0], p[1], t));
    case LINEAR_MOTION: return quat_normalized(intrinsic_xyz(p[2], p[3], p[4]));
    case OFFSET_ROTATION:
        return quat_multiply(rot(2, radians(p[1]) * sin(2 * PI * p[0] * t)), extrinsic_xy(p[3], p[4]));
    case PHONE_FLAT: {
        double w = 2 * PI * p[2];
        return yaw_pitch_roll(radians(p[1]) * sin(0.5 * w * t), radians(p[0]) * sin(0.7 * w * t),
                              radians(p[0]) * sin(w * t));
    }
    case RUNNING: {
        double th = 2 * PI * p[0] * t;
        return yaw_pitch_roll(radians(p[6]) * sin(th / 2), radians(p[4]) * sin(th), radians(p[5]) * sin(th / 2));
    }
    case ROBOT_ARM: return robot_orientation(p, t);
    default: return (Quat){NAN, NAN, NAN, NAN};
    }
}

static Vec3 velocity(const ClosedForm *m, double t) {
    const double *p = m->p;
    switch (m->profile) {
    case LEVER_ARM: return (Vec3){p[0] * p[1] * -sin(p[0] * t), p[0] * p[1] * cos(p[0] * t), 0.0};
    case INCLINE: {
        double w = 2 * PI * p[2], amplitude = p[1] * m->g / w;
        Vec3 along = quat_rotate(rot(1, radians(-p[0])), (Vec3){1.0, 0.0, 0.0});
        double s = -amplitude * cos(w * t);
        return (Vec3){s * along.x, s * along.y, s * along.z};
    }
    case LINEAR_MOTION: {
        double w = 2 * PI / p[1];
        return (Vec3){p[0] * w / 2 * sin(w * t), 0.0, 0.0};
    }
    case OFFSET_ROTATION: {
        double amp = radians(p[1]), w = 2 * PI * p[0];
        double psi = amp * sin(w * t), psi_dot = amp * w * cos(w * t);
        return (Vec3){p[2] * (-sin(psi) * psi_dot), p[2] * (cos(psi) * psi_dot), 0.0};
    }
    case PHONE_FLAT: {
        double w = 2 * PI * p[2];
        return (Vec3){p[3] * w * sin(w * t), p[3] * 0.7 * w * sin(0.7 * w * t), 0.0};
    }
    case RUNNING: {
        double w = 2 * PI * p[0], th = w * t, up = 0.0;
        for (int n = 1; n <= 4; n++) up += sin(n * th) / n;
        return (Vec3){p[2] * m->g * sin(th) / w, p[3] * m->g * 2.0 * sin(th / 2) / w, p[1] * m->g * up / (4 * w)};
    }
    default: return (Vec3){0.0, 0.0, 0.0}; /* fixed in position */
    }
}

static Vec3 cross(Vec3 a, Vec3 b) { return (Vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

void lever_force(const double r[3], const double w0[3], const double w1[3], const double turn[4], double h,
                 double f[3]) {
    Vec3 arm = {r[0], r[1], r[2]}, rate = {w1[0], w1[1], w1[2]};
    Vec3 now = cross(rate, arm);
    if (!(h > 0.0)) {
        Vec3 centripetal = cross(rate, now);
        f[0] += centripetal.x, f[1] += centripetal.y, f[2] += centripetal.z;
        return;
    }
    Vec3 before = quat_rotate(quat_conjugate(quat_load(turn)), cross((Vec3){w0[0], w0[1], w0[2]}, arm));
    f[0] += (now.x - before.x) / h, f[1] += (now.y - before.y) / h, f[2] += (now.z - before.z) / h;
}

void rotation_vector(const double quat[4], double r[3]) {
    Quat q = quat_load(quat);
    if (q.w < 0.0) q = (Quat){-q.w, -q.x, -q.y, -q.z};
    double angle = 2.0 * atan2(sqrt(q.x * q.x + q.y * q.y + q.z * q.z), q.w);
    double angle2 = angle * angle;
    double scale = angle <= 1e-3 ? 2.0 + angle2 / 12.0 + 7.0 * angle2 * angle2 / 2880.0 : angle / sin(angle / 2.0);
    r[0] = scale * q.x, r[1] = scale * q.y, r[2] = scale * q.z;
}

int closed_form_profile(const char *name) {
    for (int profile = 0; profile < N_CLOSED_FORMS; profile++)
        if (strcmp(CLOSED_FORM_NAMES[profile], name) == 0) return profile;
    return -1;
}

/* the limit of the intervals (t, t + h] as h goes to 0: the rate and specific force at t, by Richardson's
 * extrapolation (8 A(d) - 6 A(2 d) + A(4 d)) / 3 of the intervals A of d, 2 d and 4 d, whose error falls as d^3
 * (d: INSTANT_STEP s, relative beyond 1 s) while their rounding grows as 1/d: within about 1e-10 for the
 * profiles' defaults */
#define INSTANT_STEP 1e-5
static void instant_at(const ClosedForm *m, double t, double gyr[3], double f[3], double quat[4]) {
    double d = INSTANT_STEP * fmax(1.0, fabs(t)), g[3][3], a[3][3], q[4];
    for (int k = 0; k < 3; k++) closed_form_at(m, t + d * (1 << k), d * (1 << k), g[k], a[k], q);
    for (int i = 0; i < 3; i++) {
        gyr[i] = (8.0 * g[0][i] - 6.0 * g[1][i] + g[2][i]) / 3.0;
        f[i] = (8.0 * a[0][i] - 6.0 * a[1][i] + a[2][i]) / 3.0;
    }
    Quat now = orientation(m, t);
    quat[0] = now.w, quat[1] = now.x, quat[2] = now.y, quat[3] = now.z;
}

void closed_form_at(const ClosedForm *m, double t, double h, double gyr[3], double f[3], double quat[4]) {
    if (h == 0.0) {
        instant_at(m, t, gyr, f, quat);
        return;
    }
    Quat now = orientation(m, t), before = orientation(m, t - h);
    double turn[4];
    quat_store(quat_multiply(quat_conjugate(before), now), turn);
    rotation_vector(turn, gyr);
    for (int i = 0; i < 3; i++) gyr[i] /= h;
    Vec3 v = velocity(m, t), v0 = velocity(m, t - h);
    Vec3 acc = {(v.x - v0.x) / h, (v.y - v0.y) / h, (v.z - v0.z) / h + m->g};
    Vec3 sensor = quat_rotate(quat_conjugate(now), acc);
    f[0] = sensor.x, f[1] = sensor.y, f[2] = sensor.z;
    quat[0] = now.w, quat[1] = now.x, quat[2] = now.y, quat[3] = now.z;
    const double *r = lever(m);
    if (r) {
        Vec3 a = body_rate(m, t - h), b = body_rate(m, t);
        const double w0[3] = {a.x, a.y, a.z}, w1[3] = {b.x, b.y, b.z};
        lever_force(r, w0, w1, turn, h, f);
    }
}

void closed_form_run(const ClosedForm *m, const double *t, size_t n, double h, double *gyr, double *f, double *quat) {
    for (size_t k = 0; k < n; k++) closed_form_at(m, t[k], h, gyr + 3 * k, f + 3 * k, quat + 4 * k);
}
