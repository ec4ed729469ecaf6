/* human_motion.h: HumanMotion, band-limited human motion (Rizun eq. 14) with a band-limited random
 * rotation: velocity and angular rate are first-order low-passed white noise (exact
 * Ornstein-Uhlenbeck steps), the orientation their integral. Bound into Python by
 * systems/simulation/motion.py (HumanMotion, HumanStream). */
#ifndef SIM_HUMAN_MOTION_H
#define SIM_HUMAN_MOTION_H

#include <stddef.h>
#include <stdint.h>

#define HUMAN_N_STATES 10 /* v (m/s, 3), omega (rad/s, 3), q (sensor -> earth, 4) */
#define HUMAN_N_COEF 6    /* phi_v, sig_v, phi_w, sig_w, Ts (s), g (m/s^2) */
#define HUMAN_N_OUT 10    /* omega (rad/s, 3), specific force (m/s^2, 3), q (4) */

/* delta_v: density of the velocity, m/s/sqrt(Hz); omega_c: its band limit, rad/s; rot_rms: RMS
 * angular rate per axis, rad/s; rot_cutoff: its band limit, rad/s; g: gravity, m/s^2 */
typedef struct {
    double delta_v, omega_c, rot_rms, rot_cutoff, g;
} HumanParams;

/* HumanMotion's refusals: 0, or -1 with the message. */
int human_check(const HumanParams *p, char *message, size_t size);
/* the coefficients of the exact steps at sample rate fs (Hz) */
void human_coefficients(const HumanParams *p, double fs, double coef[HUMAN_N_COEF]);
/* at rest, level */
void human_initial_state(double state[HUMAN_N_STATES]);
/* one sample from 6 unit normals */
void human_step(double state[HUMAN_N_STATES], const double noise[6], const double coef[HUMAN_N_COEF],
                double out[HUMAN_N_OUT]);
/* n samples from n rows of 6 unit normals: out n rows of HUMAN_N_OUT, row-major */
void human_run(double state[HUMAN_N_STATES], const double *noise, size_t n, const double coef[HUMAN_N_COEF],
               double *out);

/* HumanMotion sample by sample from a seed: plain data. */
typedef struct {
    HumanParams params;
    uint64_t seed, k; /* the noise stream MOTION's seed, and the samples drawn */
    double h;         /* the step the coefficients are for, s (0: none yet) */
    double coef[HUMAN_N_COEF];
    double state[HUMAN_N_STATES];
} HumanStream;

void human_stream_init(HumanStream *stream, const HumanParams *params, uint64_t seed);
/* the interval (t - h, t]: out as human_step's */
void human_stream_step(HumanStream *stream, double h, double out[HUMAN_N_OUT]);

#endif
