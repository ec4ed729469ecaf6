/* gyro_offset.h: the gyroscope-offset estimator (rest detection, the Kalman filter at rest,
 * the tracking while moving), documented in blocks/stages/gyro_offset.py. */
#ifndef AF_GYRO_OFFSET_H
#define AF_GYRO_OFFSET_H

#include <stddef.h>

#include "af_params.h"
#include "stages/fields.h"

#define REST_NOISE_SIGMAS 4.5 /* the least rest_gyr in units of the gyro noise's per-axis s.d. through tau_short */
#define ARM_RATE_HZ 5.0       /* Hz: the lever arm's fit takes its samples at about this rate */
#define ARM_HIGHPASS_S 10.0   /* s: time constant of the high-pass of the fit's samples (gravity, slow drift) */
#define ARM_EXPLAINED 0.9     /* the arm is removed where the fit explains at least this share of what is left */
#define ARM_RIDGE 1e-6        /* the fit's normal matrix plus this share of its mean eigenvalue on the diagonal */
#define ARM_SHOWN_MIN 0.05    /* m/s^2: an arm is taken where the accelerations it explains reach this RMS */
#define ARM_MAX_M 3.0         /* m: a longer fitted arm is not a sensor on a turning body (a drift fitted) */
#define ARM_SAMPLES_MIN 4.0   /* the least number of fit samples that carry what the high-pass leaves, (sum |y|^2)^2 /
                               * sum |y|^4: a motion's abrupt onset, one sample of it, fits some arm */

/* The estimator's state: the gyro (rad/s) and the accelerometer (m/s^2) low-passed over tau_lp,
 * and through the short low-pass; the time at rest (s); the offset estimate b (rad/s) and its
 * covariance P ((rad/s)^2, row-major); the gyro through tau_rest (what a rest's sample measures); the
 * time since the start (s); q, sensor -> gyro frame; the Butterworth's two rows (value, derivative) of the
 * accelerometer in the gyro frame, of R (row-major) and of R.b. The online lever arm: the corrected gyro of
 * the sample before; the high-pass's low-passes of y = R.acc and X = R.A (row-major, A.r = alpha x r +
 * w x (w x r)); the fit's forgetting sums of X^T.X (xx, xy, xz, yy, yz, zz), X^T.y, |y|^2 and |y|^4 over
 * the high-passed samples; the fit's time (s); samples since its last; the arm removed (m, 0: none proven). */
#define GYRO_OFFSET_FIELDS(X)                                                                                     \
    X(lp_gyr, [3]) X(lp_acc, [3]) X(short_gyr, [3]) X(short_acc, [3]) X(rest, ) X(b, [3]) X(P, [9])             \
    X(rest_gyr_mean, [3]) X(t, ) X(q, [4]) X(acc_lp, [2][3]) X(r_lp, [2][9]) X(rb_lp, [2][3]) X(arm_gyr, [3])     \
    X(arm_y, [3]) X(arm_x, [9]) X(arm_normal, [6]) X(arm_moment, [3]) X(arm_total, ) X(arm_square, ) X(arm_time, )              \
    X(arm_phase, ) X(arm, [3])
typedef struct {
    GYRO_OFFSET_FIELDS(AF_DOUBLES)
} AfGyroOffset;
extern const AfField GYRO_OFFSET_STATE_FIELDS[];
extern const size_t GYRO_OFFSET_N_FIELDS;

/* Its coefficients at one sample time (gyro_offset_coefficients). */
typedef struct {
    double Ts;               /* s */
    double a_lp, a_short;    /* 1 - exp(-Ts/tau_lp), 1 - exp(-Ts/tau_short) */
    double a_rest;           /* 1 - exp(-Ts/tau_rest) */
    double r;                /* delta_n^2/(2 Ts): a gyro sample's variance at rest ((rad/s)^2) */
    double rest_gyr;         /* rest_gyr, at least REST_NOISE_SIGMAS delta_n/sqrt(4 tau_short) (rad/s) */
    double rest_gyr_abs, rest_acc, rest_time;
    double P0;               /* sigma_init^2 */
    double V;                /* sigma_motion^2 Ts/tau_motion, the process noise per sample (0: no tracking) */
    double W;                /* sigma_motion^4/V + sigma_motion^2, the measurement noise while moving */
    double Ad[4], Bd[2];     /* the zero-order hold of the accelerometer's Butterworth at sqrt 2/tau_acc */
    double tau_acc, settle;  /* s: the running mean's time, and no update before settle = 3 tau_acc */
    double clip;             /* the innovations' clip, 4 sigma_init (rad/s) */
    double arm_every;        /* samples from one of the lever arm's fit samples to the next (0: no lever arm) */
    double a_arm;            /* 1 - exp(-arm_every Ts/ARM_HIGHPASS_S), the high-pass's low-pass per fit sample */
    double arm_keep;         /* exp(-arm_every Ts/tau_arm): the fit's sums forget */
    double arm_floor;        /* ARM_SHOWN_MIN^2/(1 - arm_keep): the least explained sum a fit is taken on ((m/s^2)^2) */
} AfGyroOffsetCoef;

/* coefficients: from the stage's resolved parameters (AF_P_<name>) at Ts (s); 0, or -1 where one
 * is not finite (they overflow at this Ts). */
int gyro_offset_coefficients(const double params[AF_N_PARAMS], double Ts, AfGyroOffsetCoef *coef);

/* initial_state: low-passes on the first samples gyr0 (rad/s), acc0 (m/s^2), no offset. */
void gyro_offset_initial_state(const AfGyroOffsetCoef *coef, const double gyr0[3], const double acc0[3],
                               AfGyroOffset *state);

/* One sample (gyr rad/s, acc m/s^2): state in place; the offset estimate after it (rad/s), its
 * variance per axis ((rad/s)^2) and the accelerometer freed of the lever arm's accelerations (m/s^2, may be
 * acc). */
void gyro_offset_step(AfGyroOffset *state, const AfGyroOffsetCoef *coef, const double gyr[3], const double acc[3],
                      double offset[3], double variance[3], double acc_out[3]);

/* gyro_offset_step over n samples, rows of 3: gyr, acc in; offset, variance, acc_out (NULL: not written) out.
 * allowed (n values; NULL:
 * every sample): a sample at rest measures the offset only where allowed[k] is not 0 (elsewhere the tracking
 * while moving runs); resting (n values; NULL: not written): 1 where the rest had held rest_time at sample k,
 * else 0 (the rest detection alone: it does not depend on allowed or the estimate). */
void gyro_offset_run(AfGyroOffset *state, const AfGyroOffsetCoef *coef, size_t n, const double *gyr,
                     const double *acc, const unsigned char *allowed, double *offset, double *variance,
                     double *acc_out, unsigned char *resting);

#endif
