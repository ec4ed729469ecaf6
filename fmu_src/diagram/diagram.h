/* diagram.h: an exported python-control diagram as the generated tables describe it
 * (diagram_tables.h, written by systems/fmi/export/ for each exported FMU), run by
 * models/Diagram.c on the FMI plumbing.
 *
 * A diagram is a list of blocks (the leaves of the python-control interconnect, nested
 * interconnects flattened), each a kind of C step (DIAGRAM_<KIND>) with its own inputs, outputs
 * and state, and two linear maps:
 *   block input i  = sum of DIAGRAM_INPUT_TERMS with to = i:  gain * (diagram input or block output)
 *   diagram output = sum of DIAGRAM_OUTPUT_TERMS likewise (a source may also be a block input)
 * The blocks' outputs ("signals") are numbered block after block, as are their inputs and their
 * states (the diagram's state vector x is python-control's: the blocks' states in order).
 *
 * One step (the convention of the project's FMUs: after the doStep that ends at t[k+1], with the
 * inputs of sample k held over it, the outputs are the diagram's outputs at sample k as
 * control.input_output_response computes them):
 *   1. the blocks without feedthrough (DIAGRAM_LTI with D = 0) write their outputs from their state;
 *   2. the blocks with feedthrough, in DIAGRAM_ORDER, gather their inputs and take their step:
 *      outputs at sample k and next state from (state, inputs at k);
 *   3. the blocks without feedthrough gather their inputs and update their state;
 *   4. the diagram's outputs are gathered; every next state becomes the state. */
#ifndef AF_DIAGRAM_H
#define AF_DIAGRAM_H

#include <stddef.h>

/* The kinds of block, each a C step of the core (fmu_src/diagram/kinds.h). */
typedef enum {
    DIAGRAM_LTI,          /* control.StateSpace / TransferFunction: x+ = A x + B u, y = C x + D u */
    DIAGRAM_METHOD,       /* estimator_system(method, params, dt): a method's AfStepper */
    DIAGRAM_FILTER,       /* sensor_frame_system(earth_filter, dt): the sensor-frame step of a discrete filter */
    DIAGRAM_GYRO_OFFSET,  /* offset_system(dt, params) */
    DIAGRAM_HEADING,      /* heading_system(dt, params) */
    DIAGRAM_LATENCY,      /* latency_system(dt, latency, ...) */
    DIAGRAM_IMU,          /* ImuModel.system(fs) */
    DIAGRAM_MAGNETOMETER, /* systems.simulation.diagram.magnetometer_system(imu, fs) */
    DIAGRAM_HUMAN,        /* HumanMotion.system(fs) */
    DIAGRAM_CLOSED_FORM,  /* ClosedForm.system(fs): a closed-form motion profile */
    DIAGRAM_ERROR,        /* systems.simulation.diagram.attitude_error_system(fs) */
    DIAGRAM_KINDS
} DiagramKind;

/* One block. Its numbers by kind:
 *   LTI          none: its matrices are the FMU's Real parameters from `parameter` on: A (n x n), B (n x m),
 *                C (p x n), D (p x m), row-major (n = n_states, m = n_inputs, p = n_outputs); dt > 0: discrete
 *                (A, B as they are); dt = 0: continuous, held by zero-order hold over each communication step;
 *                Reals of fixed variability (read at initialisation, at each new hold and, C and D, at each step)
 *   METHOD       text: the method's name; names[i] = numbers[i]: the parameters given (n_numbers of them)
 *   FILTER       [n, Ad (n x n), Bd (n), C (n), D]: the discrete earth-frame filter at dt
 *   GYRO_OFFSET, HEADING   names[i] = numbers[i]: the parameters given (NaN: not given, as None)
 *   LATENCY      [latency (s)]
 *   IMU, MAGNETOMETER      the ImuModel's vector (22, as _core.imu_measure takes it), then fs (Hz), the rate
 *                ImuModel.system(fs) was made at (1/dt is not always fs: 1/(1/49.0) != 49.0)
 *   HUMAN        HumanMotion.coefficients(fs): [phi_v, sig_v, phi_w, sig_w, Ts, g]
 *   CLOSED_FORM  text: the profile's name; [its parameters (profile_table.py's order)..., g]
 *   ERROR        none */
typedef struct {
    const char *name;          /* the block's path in the diagram (its name, within its interconnects') */
    DiagramKind kind;
    int feedthrough;           /* 1: its outputs at sample k depend on its inputs at k */
    int start;                 /* 1: from an all-zero state it starts at rest on its first inputs, as the
                                  python-control block does (blocks/control_system.py, sample_system) */
    size_t input, n_inputs;    /* its inputs: block inputs input ... input + n_inputs - 1 */
    size_t output, n_outputs;  /* its outputs: signals output ... */
    size_t state, n_states;    /* its state: x[state] ... */
    double dt;                 /* its sample time (s); 0: continuous (LTI) */
    const char *text;          /* METHOD, CLOSED_FORM: a name; else NULL */
    const char *const *names;  /* METHOD, GYRO_OFFSET, HEADING: the given parameters' names; else NULL */
    const double *numbers;     /* by kind, above; NULL where none */
    size_t n_numbers;
    size_t parameter;          /* LTI: the index among the FMU's Reals of A[0,0] (its matrices follow) */
} DiagramBlock;

#define DIAGRAM_LTI_MAX 32 /* the largest n + m of an LTI block an FMU takes (a state's check holds the
                              hold's workspace, 13 (n + m)^2 doubles, on the stack) */

/* Where a term takes its value. */
typedef enum { DIAGRAM_FROM_INPUT, DIAGRAM_FROM_SIGNAL, DIAGRAM_FROM_BLOCK_INPUT } DiagramSource;

/* One term of a linear map: value[to] += gain * source[from]. */
typedef struct {
    size_t to;
    DiagramSource source;
    size_t from;
    double gain;
} DiagramTerm;

#endif
