/* human_motion.h: HumanMotion, band-limited human motion (Rizun eq. 14) with a band-limited random
 * rotation on a time grid: velocity and angular rate are first-order low-passed white noise (exact
 * Ornstein-Uhlenbeck steps from one grid point to the next, a draw of 6 unit normals per grid cell);
 * within a cell the angular rate and the acceleration are constant (the velocity linear), so the
 * orientation and the velocity are exact at every time. A lever arm puts the sensor at r (body frame, m) from
 * the motion's point: its specific force adds the mean over each interval of d/dt (R (omega x r)), exact for
 * the rate constant within each cell and stepping between them (closed_form.h, lever_force). Bound into Python by
 * systems/simulation/motion.py (HumanMotion, HumanStream). */
#ifndef SIM_HUMAN_MOTION_H
#define SIM_HUMAN_MOTION_H

#include <stddef.h>
#include <stdint.h>

#define HUMAN_N_STATES 10 /* v (m/s, 3), omega (rad/s, 3), q (sensor -> earth, 4) */
#define HUMAN_N_COEF 9    /* phi_v, sig_v, phi_w, sig_w, Ts (s), g (m/s^2), lever (m, 3) */
#define HUMAN_N_OUT 10    /* omega (rad/s, 3), specific force (m/s^2, 3), q (4) */
#define HUMAN_MAX_CELLS 4194304.0 /* grid cells one step may draw (about 2 s of work; 70 min of the default grid) */
#define HUMAN_MAX_GRID 9007199254740992.0 /* grid cells a stream draws in all (2^53: counts and times stay exact and
                                           * the 64-bit count far from wrapping) */

/* delta_v: density of the velocity, m/s/sqrt(Hz); omega_c: its band limit, rad/s; rot_rms: RMS
 * angular rate per axis, rad/s; rot_cutoff: its band limit, rad/s; g: gravity, m/s^2; lever: the sensor's
 * position from the motion's point, body frame, m (their ranges: profile_table.py's, checked by
 * profile_params.h) */
typedef struct {
    double delta_v, omega_c, rot_rms, rot_cutoff, g, lever[3];
} HumanParams;

/* the coefficients of the exact steps at sample rate fs (Hz): one grid cell of 1/fs s */
void human_coefficients(const HumanParams *p, double fs, double coef[HUMAN_N_COEF]);
/* at rest, level */
void human_initial_state(double state[HUMAN_N_STATES]);
/* one grid cell from 6 unit normals: the state from the cell's start to its end; out its rate,
 * the specific force at its end (the cell's acceleration) and q at its end */
void human_step(double state[HUMAN_N_STATES], const double noise[6], const double coef[HUMAN_N_COEF],
                double out[HUMAN_N_OUT]);
/* n samples from n rows of 6 unit normals, a grid cell each: out n rows of HUMAN_N_OUT, row-major */
void human_run(double state[HUMAN_N_STATES], const double *noise, size_t n, const double coef[HUMAN_N_COEF],
               double *out);

/* HumanMotion at any times from a seed, on a grid of cells (k grid, (k + 1) grid] from time 0: plain data. */
typedef struct {
    HumanParams params;
    uint64_t seed, k;  /* the noise stream MOTION's seed, and the cells drawn (the current cell: k - 1) */
    double grid;       /* s */
    double coef[HUMAN_N_COEF];
    double state[HUMAN_N_STATES]; /* at the current cell's end: v, its rate, q */
    double v0[3], q0[4];          /* at the current cell's start */
    double acc[3];                /* the current cell's acceleration, earth frame, m/s^2 */
    double t;                     /* the end of the last interval stepped, s */
} HumanStream;

/* at rest, level at time 0; grid (s) in its range (profile_table.py's, checked by profile_params.h) */
void human_stream_init(HumanStream *stream, const HumanParams *params, double grid, uint64_t seed);
/* the interval (start, end] (s from time 0; start not before the last interval's end, to rounding):
 * out the rate that turns q(start) into q(end) over it (the rotation vector over end - start), the
 * specific force R(end)^T (mean acceleration over it + g z) and q(end); where end - start rounds to 0,
 * the rate and acceleration at start. 0, or -1 with the refusal (an interval that is not finite,
 * starts before the last one ends, needs more than HUMAN_MAX_CELLS grid cells or ends beyond
 * HUMAN_MAX_GRID of them) and the stream as it was. */
int human_stream_step(HumanStream *stream, double start, double end, double out[HUMAN_N_OUT], char *message,
                      size_t size);

/* Whether s (bytes nobody vouches for, e.g. an FMU state's) is a stream human_stream_init made as it made
 * configured, stepped on: its parameters, seed, grid and coefficients configured's, its time t finite and
 * not negative, its cells drawn those that reach t and HUMAN_MAX_GRID at most, its states finite, its
 * quaternions unit ones. 0, or -1 with a message. */
int human_stream_validate(const HumanStream *s, const HumanStream *configured, char *message, size_t size);

#endif
