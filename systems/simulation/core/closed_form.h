/* closed_form.h: the motions given by closed forms of orientation R(t) (sensor -> earth) and
 * earth-frame velocity v(t), sampled over (t - h, t]: gyr is the rotation vector of R(t-h)^T R(t)
 * over h, the specific force R(t)^T ((v(t) - v(t-h))/h + g z).
 * Python twin: systems/simulation/motion.py (ClosedFormMotion.at and the profiles steady_lever_arm,
 * incline_oscillation, coning, sine_rotation, step_rotation, linear_motion, offset_rotation). */
#ifndef SIM_CLOSED_FORM_H
#define SIM_CLOSED_FORM_H

#define CLOSED_FORM_MAX_PARAMS 5

typedef enum {
    LEVER_ARM,       /* rate (rad/s), radius (m) */
    INCLINE,         /* incline_deg, peak_acc_g (1), frequency (Hz) */
    CONING,          /* theta (rad), rate (rad/s) */
    SINE_ROTATION,   /* amplitude_deg, frequency (Hz), inclination_deg */
    STEP_ROTATION,   /* hold (s), ramp (s) */
    LINEAR_MOTION,   /* amplitude (m), period (s), mount_x_deg, mount_y_deg, mount_z_deg */
    OFFSET_ROTATION, /* frequency (Hz), amplitude_deg, radius (m), inclination_deg, pitch_deg */
    N_CLOSED_FORMS
} ClosedFormProfile;

/* a profile with its parameters, in the order of the Python Profile's params (above), and gravity
 * (m/s^2) */
typedef struct {
    ClosedFormProfile profile;
    double p[CLOSED_FORM_MAX_PARAMS];
    double g;
} ClosedForm;

/* the interval (t - h, t]: gyr (rad/s), specific force f (m/s^2, sensor coordinates), quat (at t) */
void closed_form_at(const ClosedForm *motion, double t, double h, double gyr[3], double f[3], double quat[4]);

#endif
