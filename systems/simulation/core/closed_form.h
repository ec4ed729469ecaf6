/* closed_form.h: the motions given by closed forms of orientation R(t) (sensor -> earth) and
 * earth-frame velocity v(t), sampled over (t - h, t]: gyr is the rotation vector of R(t-h)^T R(t)
 * over h (so integrating it reproduces R exactly), the specific force R(t)^T ((v(t) - v(t-h))/h + g z).
 * The profiles' names and parameters: systems/simulation/profile_table.py; bound into Python by
 * systems/simulation/motion.py (ClosedForm). */
#ifndef SIM_CLOSED_FORM_H
#define SIM_CLOSED_FORM_H

#include <stddef.h>

#include "sim_profiles.h" /* SIM_PROFILE_MAX_PARAMS (generated from profile_table.py) */

#define CLOSED_FORM_MAX_PARAMS SIM_PROFILE_MAX_PARAMS

typedef enum {
    /* Rizun 2.4: turning at rate (rad/s) about the vertical on an arm of radius (m), the sensor
     * mounted with roll 20 deg and pitch -10 deg on the arm (so its mean centripetal acceleration
     * in sensor coordinates is constant, not zero): R = Rz(rate t) R_mount */
    LEVER_ARM,
    /* Rizun 2.5 (Fig. 3): harmonic motion along an incline of incline_deg, sensor x up the slope, no
     * rotation; acceleration peak_acc_g (1) g sin(2 pi frequency (Hz) t) along the incline */
    INCLINE,
    /* Luinge's coning, half-angle theta (rad) at rate (rad/s), fixed in position:
     * R = Rz(rate t) Rx(theta) Rz(-rate t) */
    CONING,
    /* Tseng 1-2: pitch amplitude_deg sin(2 pi frequency (Hz) t) about the platform's y, the IMU
     * inclined by inclination_deg about its x: R = Ry(pitch) Rx(inclination) */
    SINE_ROTATION,
    /* Tseng 3: pitch steps of STEP_SIZES_DEG (closed_form.c), each held hold (s) and back to 0 for
     * hold, each step a raised-cosine ramp (s); repeated after the last */
    STEP_ROTATION,
    /* Tseng 4: back and forth along the earth x, x(t) = amplitude (m) (1 - cos(2 pi t/period (s)))/2,
     * the IMU mounted rotated by mount_x_deg, mount_y_deg, mount_z_deg about x, the new y, the new z */
    LINEAR_MOTION,
    /* Tseng 5: yaw psi = amplitude_deg sin(2 pi frequency (Hz) t) on an arm of radius (m), the IMU
     * mounted with inclination_deg about x and pitch_deg about y: R = Rz(psi) R_mount, position
     * radius (cos psi, sin psi, 0) */
    OFFSET_ROTATION,
    /* a phone (mostly) flat on a table or a hand: R = Rz(yaw) Ry(pitch) Rx(roll) with roll tilt_deg
     * sin(w t), pitch tilt_deg sin(0.7 w t), yaw yaw_deg sin(0.5 w t), w = 2 pi frequency (Hz); sliding
     * about, position travel (m) (1 - cos(w t), 1 - cos(0.7 w t), 0) */
    PHONE_FLAT,
    /* running at step_frequency (Hz), phase th = 2 pi step_frequency t: vertical acceleration impact_g g
     * (cos th + cos 2th + cos 3th + cos 4th)/4 (impacts of impact_g g, about -0.38 impact_g g between
     * them), forward forward_g g cos th, sideways sway_g g cos(th/2) (a stride: two steps); R = Rz(yaw)
     * Ry(pitch) Rx(roll), pitch pitch_deg sin th, roll roll_deg sin(th/2), yaw yaw_deg sin(th/2) */
    RUNNING,
    /* an industrial robot's wrist, fixed in position, turning through ROBOT_MOVES (closed_form.c) of
     * angle_deg each, a move taking move (s) along a minimum-jerk law s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5,
     * then dwell (s) at rest; the moves return to the start and repeat; R = W_j Rot(u_j, s angle_j). The
     * sensor at the lever arm lever_x, lever_y, lever_z (m, body frame) from the wrist (lever_force) */
    ROBOT_ARM,
    N_CLOSED_FORMS
} ClosedFormProfile; /* PHONE_FLAT, RUNNING and ROBOT_ARM start level, at rest (v(0) = 0) */

/* the profiles' names, in the order above (profile_table.py's) */
extern const char *const CLOSED_FORM_NAMES[N_CLOSED_FORMS];

/* a profile with its parameters, in the order of profile_table.py's (above), and gravity (m/s^2) */
typedef struct {
    ClosedFormProfile profile;
    double p[CLOSED_FORM_MAX_PARAMS];
    double g;
} ClosedForm;

/* The lever arm's share of the specific force over an interval of h s added to f (sensor coordinates at its
 * end, m/s^2): the mean acceleration of a point at r (body frame, m) from the motion's point,
 * (R1 (w1 x r) - R0 (w0 x r))/h turned into the body at the end, with w0, w1 the body rates (rad/s) at the
 * interval's start and end and turn = R0^T R1 the rotation over it: (w1 x r - turn^T (w0 x r))/h, whose limit
 * is w x (w x r) + alpha x r; where h is 0 (not positive), the centripetal w1 x (w1 x r). */
void lever_force(const double r[3], const double w0[3], const double w1[3], const double turn[4], double h,
                 double f[3]);
/* Rotation.as_rotvec: the rotation vector r (rad) of the unit quaternion quat, taken with w >= 0 */
void rotation_vector(const double quat[4], double r[3]);
/* the profile of that name: its number, or -1 */
int closed_form_profile(const char *name);
/* the interval (t - h, t]: gyr (rad/s), specific force f (m/s^2, sensor coordinates), quat (at t); h = 0: the
 * instant t, its rate and specific force (their limit over (t, t + h], within about 1e-10) */
void closed_form_at(const ClosedForm *motion, double t, double h, double gyr[3], double f[3], double quat[4]);
/* the intervals ending at the n times t, each h long: gyr, f (n rows of 3), quat (n rows of 4) */
void closed_form_run(const ClosedForm *motion, const double *t, size_t n, double h, double *gyr, double *f,
                     double *quat);

#endif
