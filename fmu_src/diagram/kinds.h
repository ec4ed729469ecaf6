/* kinds.h: the C step of each kind of diagram block (diagram.h, DiagramKind) on the project's C core,
 * as the python-control block of that kind steps (blocks/control_system.py, sample_system): its
 * coefficients configured from the block's numbers, its start, its step and the check of its state.
 * A block's state is its slice of the diagram's state vector (python-control's, doubles); its inputs
 * and outputs are its slices of the block inputs and the signals. Units as the blocks': rad/s, m/s^2,
 * uT, s. */
#ifndef AF_DIAGRAM_KINDS_H
#define AF_DIAGRAM_KINDS_H

#include <stddef.h>

#include "closed_form.h"
#include "diagram/diagram.h"
#include "human_motion.h"
#include "methods/registry.h"
#include "sensor.h"
#include "stages/gyro_offset.h"
#include "stages/heading.h"

/* An LTI block's shape: A (n x n), B (n x m), C (p x n), D (p x m), row-major, from the Real at the
 * block's `parameter` on; the A and B it steps with are at `pool` of the model's pool of LTI doubles
 * (A then B), as they are (discrete) or held over the communication step (continuous). */
typedef struct {
    size_t n, m, p;
    size_t pool;
    int continuous; /* 1: dt = 0 */
} LtiCoef;

/* IMU, MAGNETOMETER: the sensor and its sample rate (Hz). */
typedef struct {
    ImuParams params;
    double fs;
} ImuCoef;

/* A block's coefficients by kind: plain data (copied into FMU states, compared bit for bit). */
typedef union {
    LtiCoef lti;
    AfStepper stepper;             /* METHOD, FILTER */
    AfGyroOffsetCoef gyro_offset;
    AfHeadingCoef heading;
    double latency;                /* LATENCY, s */
    ImuCoef imu;                   /* IMU, MAGNETOMETER */
    double human[HUMAN_N_COEF];    /* HumanMotion.coefficients */
    ClosedForm closed_form;
} KindCoef;

/* The matrices an LTI block steps with: A, B (the pool's), C, D (the Reals'). */
typedef struct {
    const double *A, *B, *C, *D;
} LtiMatrices;

/* The kind's name as blocks/control_system.py's CStep names it ("lti", "method", ...), or "unknown". */
const char *kind_name(DiagramKind kind);

/* The block's coefficients (all bytes of *coef set) from its numbers, names and text, checked as the
 * Python block checks them (the core's refusals), its inputs, outputs and states counted against its
 * kind's; an LTI block's matrices checked within the n_reals Reals and finite, and refused where it
 * was exported without feedthrough but D has a non-zero entry; coef->lti.pool is left 0 for the caller
 * to place. 0, or -1 with the reason in message (size bytes; the block not named). */
int kind_configure(const DiagramBlock *block, const double *reals, size_t n_reals, KindCoef *coef, char *message,
                   size_t size);

/* An LTI block's output y = C x + D u (u NULL: D taken as 0, a block without feedthrough). */
void lti_output(const LtiCoef *c, const LtiMatrices *lti, const double *x, const double *u, double *y);

/* An LTI block's next state next = A x + B u (next apart from x). */
void lti_update(const LtiCoef *c, const LtiMatrices *lti, const double *x, const double *u, double *next);

/* A block with feedthrough on one sample: its state x and inputs u at k give its outputs y at k and
 * its next state (next apart from x); where it starts (block->start) and x is all zero, it first
 * starts at rest on u, as sample_system does. lti: the matrices of an LTI block, else unused. */
void kind_step(const DiagramBlock *block, const KindCoef *coef, const LtiMatrices *lti, const double *x,
               const double *u, double *y, double *next);

/* Whether state (block->n_states doubles, bytes nobody vouches for) is one the configured block can
 * step from: finite; a method's all zero (not started) or with a unit quaternion (stepper_state_valid);
 * a closed form's sample count whole and not negative. 0, or -1 with the reason in message. */
int kind_validate(const DiagramBlock *block, const KindCoef *coef, const double *state, char *message, size_t size);

#endif
