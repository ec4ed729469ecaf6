/* Diagram.c: the model of an FMU exported from a python-control diagram (systems/fmi/export/): the
 * blocks, their connections and the initial state the exporter wrote into diagram_tables.h
 * (diagram/diagram.h), each block stepped by its kind's C step (diagram/kinds.h). After the step that
 * ends at t[k+1] the outputs are the diagram's at sample k, as control.input_output_response gives
 * them, the inputs of sample k held over the step; before the first step (in Initialization Mode and after it),
 * sample 0's, from the initial state and the inputs as they are. A discrete diagram (DIAGRAM_DT > 0) runs on the grid of
 * its sample time from the start time (timing.h: grid_samples): a step runs the samples it reaches, its inputs held,
 * none (a master's shortfall of picoseconds, half a sample) holding state and outputs, several in turn; a
 * continuous one (LTI blocks only) takes any step, its blocks held over it by zero-order hold. */
#include <math.h>
#include <string.h>

#include "diagram_tables.h"
#include "diagram/kinds.h"
#include "filters/matrix.h"
#include "messages.h"
#include "stages/timing.h"

#define MESSAGE_SIZE 1024
#define AT_LEAST_1(n) ((n) > 0 ? (n) : 1) /* C99 has no empty arrays */
#define HOLD_WORK ZERO_ORDER_HOLD_WORK(DIAGRAM_LTI_SIZE, 0) /* any LTI block's hold: n + m <= DIAGRAM_LTI_SIZE */

#if DIAGRAM_LTI_SIZE > DIAGRAM_LTI_MAX
#error "an LTI block of the diagram has more than DIAGRAM_LTI_MAX states and inputs"
#endif
typedef char inputs_are_reals[DIAGRAM_INPUT0 + DIAGRAM_N_INPUTS <= N_REALS ? 1 : -1];
typedef char outputs_are_reals[DIAGRAM_OUTPUT0 + DIAGRAM_N_OUTPUTS <= N_REALS ? 1 : -1];

typedef struct {
    KindCoef coef[AT_LEAST_1(DIAGRAM_N_BLOCKS)]; /* each block's, as initialise configures it */
    double lti[AT_LEAST_1(DIAGRAM_LTI_DOUBLES)]; /* each LTI block's A then B that it steps with (LtiCoef.pool): its
                                                    own where h is 0, held over h (continuous blocks) where not */
    double h;                                    /* s: the step the continuous blocks are held over; 0: none yet */
    int noted_step;      /* a step size other than the first was logged (once: a master with variable steps would
                            log each) */
    double x[AT_LEAST_1(DIAGRAM_N_STATES)]; /* the diagram's state: the blocks' states in order */
    /* one step's scratch, written before it is read */
    double next[AT_LEAST_1(DIAGRAM_N_STATES)];
    double signals[AT_LEAST_1(DIAGRAM_N_SIGNALS)];
    double inputs[AT_LEAST_1(DIAGRAM_N_BLOCK_INPUTS)];
    double outputs[AT_LEAST_1(DIAGRAM_N_OUTPUTS)];
    double work[AT_LEAST_1(HOLD_WORK)];
} Model;

/* the counts as constants of their own: a loop to a count of 0 then compares with no constant 0 (gcc's
 * -Wtype-limits) */
static const size_t n_blocks = DIAGRAM_N_BLOCKS, n_states = DIAGRAM_N_STATES, n_signals = DIAGRAM_N_SIGNALS,
                    n_block_inputs = DIAGRAM_N_BLOCK_INPUTS, n_inputs = DIAGRAM_N_INPUTS,
                    n_outputs = DIAGRAM_N_OUTPUTS, n_input_terms = DIAGRAM_N_INPUT_TERMS,
                    n_output_terms = DIAGRAM_N_OUTPUT_TERMS;

/* ---- the tables checked at initialisation */

/* whether the range first ... first + n - 1 is within count */
static int within(size_t first, size_t n, size_t count)
{
    return n <= count && first <= count - n;
}

/* the block whose inputs (inputs 1) or outputs (0) hold index (the blocks' checked: numbered block after
 * block, the last block whose first is at most index) */
static size_t block_of(size_t index, int inputs)
{
    size_t b = 0;
    while (b + 1 < n_blocks && (inputs ? DIAGRAM_BLOCKS[b + 1].input : DIAGRAM_BLOCKS[b + 1].output) <= index)
        b++;
    return b;
}

/* the block's name as Python shows a string, into name (64 bytes) */
static const char *block_name(const DiagramBlock *b, char name[64])
{
    return b->name ? str_repr(b->name, name, 64) : "None";
}

/* 0, or -1 with the refusal logged unless the blocks' inputs, outputs and states are numbered block after
 * block, as many as the diagram's counts */
static int check_blocks(Fmi2Instance *instance)
{
    size_t inputs = 0, outputs = 0, states = 0;
    char name[64];
    for (size_t b = 0; b < n_blocks; b++) {
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (block->input != inputs || block->output != outputs || block->state != states ||
            !within(inputs, block->n_inputs, n_block_inputs) ||
            !within(outputs, block->n_outputs, n_signals) || !within(states, block->n_states, n_states)) {
            fmi2_log(instance, fmi2Error, "invalid diagram: block %lu, %s, does not take the next of the %lu block "
                     "inputs, %lu signals and %lu states (its inputs from %lu, outputs from %lu, state from %lu; "
                     "%lu, %lu and %lu of them)", (unsigned long)b, block_name(block, name),
                     (unsigned long)n_block_inputs, (unsigned long)n_signals,
                     (unsigned long)n_states, (unsigned long)block->input, (unsigned long)block->output,
                     (unsigned long)block->state, (unsigned long)block->n_inputs, (unsigned long)block->n_outputs,
                     (unsigned long)block->n_states);
            return -1;
        }
        inputs += block->n_inputs, outputs += block->n_outputs, states += block->n_states;
    }
    if (inputs != n_block_inputs || outputs != n_signals || states != n_states) {
        fmi2_log(instance, fmi2Error, "invalid diagram: its blocks have %lu inputs, %lu outputs and %lu states, its "
                 "counts are %lu, %lu and %lu", (unsigned long)inputs, (unsigned long)outputs, (unsigned long)states,
                 (unsigned long)n_block_inputs, (unsigned long)n_signals,
                 (unsigned long)n_states);
        return -1;
    }
    return 0;
}

/* 0, or -1 with the refusal logged unless the n terms of one map (inputs 1: DIAGRAM_INPUT_TERMS, whose
 * sources are diagram inputs and signals; 0: DIAGRAM_OUTPUT_TERMS, also block inputs) are within the counts */
static int check_terms(Fmi2Instance *instance, const DiagramTerm *terms, size_t n, int inputs)
{
    const size_t targets = inputs ? n_block_inputs : n_outputs;
    char value[FLOAT_REPR_SIZE];
    for (size_t k = 0; k < n; k++) {
        const DiagramTerm *t = &terms[k];
        size_t sources = t->source == DIAGRAM_FROM_INPUT    ? n_inputs
                         : t->source == DIAGRAM_FROM_SIGNAL ? n_signals
                         : t->source == DIAGRAM_FROM_BLOCK_INPUT && !inputs ? n_block_inputs
                                                                            : 0;
        if (t->to >= targets || t->from >= sources || !isfinite(t->gain)) {
            fmi2_log(instance, fmi2Error, "invalid diagram: %s[%lu] (to %lu, source %d, from %lu, gain %s) is no term "
                     "of %lu %s from %s", inputs ? "DIAGRAM_INPUT_TERMS" : "DIAGRAM_OUTPUT_TERMS", (unsigned long)k,
                     (unsigned long)t->to, (int)t->source, (unsigned long)t->from, float_repr(t->gain, value),
                     (unsigned long)targets, inputs ? "block inputs" : "outputs",
                     inputs ? "a diagram input or a signal" : "a diagram input, a signal or a block input");
            return -1;
        }
    }
    return 0;
}

/* 0, or -1 with the refusal logged unless DIAGRAM_ORDER has every block once, those without feedthrough
 * first, each block with feedthrough after those with feedthrough whose outputs it takes */
static int check_order(Fmi2Instance *instance)
{
    size_t position[AT_LEAST_1(DIAGRAM_N_BLOCKS)];
    char to[64], from[64];
    for (size_t b = 0; b < n_blocks; b++) position[b] = n_blocks;
    for (size_t p = 0; p < n_blocks; p++) {
        size_t b = DIAGRAM_ORDER[p];
        if (b >= n_blocks || position[b] < n_blocks ||
            (p > 0 && DIAGRAM_BLOCKS[DIAGRAM_ORDER[p - 1]].feedthrough && !DIAGRAM_BLOCKS[b].feedthrough)) {
            fmi2_log(instance, fmi2Error, "invalid diagram: DIAGRAM_ORDER[%lu] = %lu is not the next of its %lu "
                     "blocks, each once, those without feedthrough first", (unsigned long)p, (unsigned long)b,
                     (unsigned long)n_blocks);
            return -1;
        }
        position[b] = p;
    }
    for (size_t k = 0; k < n_input_terms; k++) {
        const DiagramTerm *t = &DIAGRAM_INPUT_TERMS[k];
        if (t->source != DIAGRAM_FROM_SIGNAL) continue;
        size_t b = block_of(t->to, 1), source = block_of(t->from, 0);
        if (DIAGRAM_BLOCKS[b].feedthrough && DIAGRAM_BLOCKS[source].feedthrough && position[source] >= position[b]) {
            fmi2_log(instance, fmi2Error, "invalid diagram: block %s takes the outputs of block %s, which "
                     "DIAGRAM_ORDER does not step before it", block_name(&DIAGRAM_BLOCKS[b], to),
                     block_name(&DIAGRAM_BLOCKS[source], from));
            return -1;
        }
    }
    return 0;
}

/* ---- the LTI blocks' matrices */

/* the block's matrices: A, B the pool's, C, D the Reals' */
static LtiMatrices matrices(const Model *model, const fmi2Real *r, size_t b)
{
    const LtiCoef *c = &model->coef[b].lti;
    const double *C = r + DIAGRAM_BLOCKS[b].parameter + c->n * c->n + c->n * c->m;
    return (LtiMatrices){model->lti + c->pool, model->lti + c->pool + c->n * c->n, C, C + c->p * c->n};
}

/* every LTI block's own A and B (the Reals') into the pool */
static void own_matrices(Model *model, const fmi2Real *r)
{
    for (size_t b = 0; b < n_blocks; b++) {
        const LtiCoef *c = &model->coef[b].lti;
        if (DIAGRAM_BLOCKS[b].kind == DIAGRAM_LTI)
            memcpy(model->lti + c->pool, r + DIAGRAM_BLOCKS[b].parameter, (c->n * c->n + c->n * c->m) * sizeof(double));
    }
}

/* the continuous blocks' own A and B in pool held over h (s) in place (work: HOLD_WORK doubles); the block
 * whose hold is not finite, or n_blocks */
static size_t hold_pool(const KindCoef *coef, double *pool, double h, double *work)
{
    size_t refused = n_blocks;
    for (size_t b = 0; b < n_blocks; b++) {
        const LtiCoef *c = &coef[b].lti;
        if (DIAGRAM_BLOCKS[b].kind != DIAGRAM_LTI || !c->continuous) continue;
        double *A = pool + c->pool, *B = A + c->n * c->n;
        zero_order_hold((int)c->n, (int)c->m, A, B, h, A, B, work);
        for (size_t i = 0; i < c->n * (c->n + c->m) && refused == n_blocks; i++)
            if (!isfinite(A[i])) refused = b;
    }
    return refused;
}

/* a continuous diagram's blocks held over h (s) where h is new to them (noted once after the first): 0, or -1
 * with the refusal logged and the blocks as configured */
static int hold(Fmi2Instance *instance, Model *model, double h)
{
    char a[FLOAT_REPR_SIZE], name[64];
    if (model->h != 0.0 && same_step(h, model->h)) return 0;
    if (model->h != 0.0 && !model->noted_step) {
        model->noted_step = 1;
        fmi2_log(instance, fmi2OK, "communication step %g s differs from the one before, %g s: the diagram's "
                 "continuous blocks held over it (and, without further notes, over every other step size)", h,
                 model->h);
    }
    own_matrices(model, instance->reals);
    size_t refused = hold_pool(model->coef, model->lti, h, model->work);
    if (refused == n_blocks) {
        model->h = h;
        return 0;
    }
    own_matrices(model, instance->reals);
    model->h = 0.0;
    fmi2_log(instance, fmi2Error, "block %s held over a step of %s s overflows the arithmetic; the diagram's state "
             "and outputs held", block_name(&DIAGRAM_BLOCKS[refused], name), float_repr(h, a));
    return -1;
}

/* ---- the model */

static fmi2Status initialise(Fmi2Instance *instance)
{
    Model *model = instance->state;
    const fmi2Real *r = instance->reals;
    char message[MESSAGE_SIZE], name[64], a[FLOAT_REPR_SIZE], b2[FLOAT_REPR_SIZE];
    size_t pool = 0;
    if (!(isfinite(DIAGRAM_DT) && DIAGRAM_DT >= 0.0)) {
        fmi2_log(instance, fmi2Error, "invalid diagram: its sample time DIAGRAM_DT is %s, not a finite number of "
                 "seconds, 0 or more", float_repr(DIAGRAM_DT, a));
        return fmi2Error;
    }
    if (check_blocks(instance) || check_terms(instance, DIAGRAM_INPUT_TERMS, n_input_terms, 1) ||
        check_terms(instance, DIAGRAM_OUTPUT_TERMS, n_output_terms, 0) || check_order(instance))
        return fmi2Error;
    for (size_t b = 0; b < n_blocks; b++) {
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        LtiCoef *c = &model->coef[b].lti;
        if (kind_configure(block, r, N_REALS, &model->coef[b], message, sizeof message)) {
            fmi2_log(instance, fmi2Error, "invalid diagram block %s (%s): %s", block_name(block, name),
                     kind_name(block->kind), message);
            return fmi2Error;
        }
        if (DIAGRAM_DT > 0.0 ? block->dt != DIAGRAM_DT : block->kind != DIAGRAM_LTI || block->dt != 0.0) {
            fmi2_log(instance, fmi2Error, "invalid diagram block %s (%s): its sample time %s s is not the "
                     "diagram's, %s s (0: continuous, LTI blocks only)", block_name(block, name),
                     kind_name(block->kind), float_repr(block->dt, a), float_repr(DIAGRAM_DT, b2));
            return fmi2Error;
        }
        if (block->kind != DIAGRAM_LTI) continue;
        if (c->n + c->m > DIAGRAM_LTI_SIZE || c->n * (c->n + c->m) > DIAGRAM_LTI_DOUBLES - pool) {
            fmi2_log(instance, fmi2Error, "invalid diagram block %s (lti): its %lu states and %lu inputs exceed "
                     "DIAGRAM_LTI_SIZE (%d) or the room left of DIAGRAM_LTI_DOUBLES (%d)", block_name(block, name),
                     (unsigned long)c->n, (unsigned long)c->m, DIAGRAM_LTI_SIZE, DIAGRAM_LTI_DOUBLES);
            return fmi2Error;
        }
        c->pool = pool;
        pool += c->n * (c->n + c->m);
    }
    if (pool != DIAGRAM_LTI_DOUBLES) {
        fmi2_log(instance, fmi2Error, "invalid diagram: its LTI blocks' A and B take %lu numbers, not "
                 "DIAGRAM_LTI_DOUBLES (%d)", (unsigned long)pool, DIAGRAM_LTI_DOUBLES);
        return fmi2Error;
    }
    own_matrices(model, r);
    for (size_t i = 0; i < n_states; i++) model->x[i] = DIAGRAM_X0[i];
    for (size_t b = 0; b < n_blocks; b++) {
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (kind_validate(block, &model->coef[b], model->x + block->state, message, sizeof message)) {
            fmi2_log(instance, fmi2Error, "invalid diagram block %s (%s): in its initial state (DIAGRAM_X0) %s",
                     block_name(block, name), kind_name(block->kind), message);
            return fmi2Error;
        }
    }
    model->h = 0.0;
    model->noted_step = 0;
    return fmi2OK;
}

/* the value of a term's source */
static double source_value(const Model *model, const fmi2Real *r, const DiagramTerm *t)
{
    switch (t->source) {
    case DIAGRAM_FROM_INPUT: return r[DIAGRAM_INPUT0 + t->from];
    case DIAGRAM_FROM_SIGNAL: return model->signals[t->from];
    default: return model->inputs[t->from]; /* DIAGRAM_FROM_BLOCK_INPUT */
    }
}

/* the block's inputs from their terms */
static void gather(Model *model, const fmi2Real *r, const DiagramBlock *block)
{
    for (size_t i = 0; i < block->n_inputs; i++) model->inputs[block->input + i] = 0.0;
    for (size_t k = 0; k < n_input_terms; k++) {
        const DiagramTerm *t = &DIAGRAM_INPUT_TERMS[k];
        if (t->to >= block->input && t->to - block->input < block->n_inputs)
            model->inputs[t->to] += t->gain * source_value(model, r, t);
    }
}

/* the block whose outputs or next state are not finite, else n_blocks */
static size_t not_finite(const Model *model)
{
    for (size_t b = 0; b < n_blocks; b++) {
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        for (size_t i = 0; i < block->n_outputs; i++)
            if (!isfinite(model->signals[block->output + i])) return b;
        for (size_t i = 0; i < block->n_states; i++)
            if (!isfinite(model->next[block->state + i])) return b;
    }
    return n_blocks;
}

/* one sample of the diagram at its state and the inputs as they are: the blocks' outputs and next state, the
 * diagram's outputs (model->signals, next, outputs); the block whose outputs or next state are not finite,
 * n_blocks + 1 where the diagram's outputs are not, else n_blocks */
static size_t evaluate(Model *model, const fmi2Real *r)
{
    /* 1: the blocks without feedthrough, their outputs from their state */
    for (size_t p = 0; p < n_blocks; p++) {
        size_t b = DIAGRAM_ORDER[p];
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (block->feedthrough) continue;
        LtiMatrices lti = matrices(model, r, b);
        lti_output(&model->coef[b].lti, &lti, model->x + block->state, NULL, model->signals + block->output);
    }
    /* 2: the blocks with feedthrough, in order */
    for (size_t p = 0; p < n_blocks; p++) {
        size_t b = DIAGRAM_ORDER[p];
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (!block->feedthrough) continue;
        LtiMatrices lti = block->kind == DIAGRAM_LTI ? matrices(model, r, b) : (LtiMatrices){NULL, NULL, NULL, NULL};
        gather(model, r, block);
        kind_step(block, &model->coef[b], &lti, model->x + block->state, model->inputs + block->input,
                  model->signals + block->output, model->next + block->state);
    }
    /* 3: the blocks without feedthrough, their next state */
    for (size_t p = 0; p < n_blocks; p++) {
        size_t b = DIAGRAM_ORDER[p];
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (block->feedthrough) continue;
        LtiMatrices lti = matrices(model, r, b);
        gather(model, r, block);
        lti_update(&model->coef[b].lti, &lti, model->x + block->state, model->inputs + block->input,
                   model->next + block->state);
    }
    /* 4: the diagram's outputs */
    for (size_t i = 0; i < n_outputs; i++) model->outputs[i] = 0.0;
    for (size_t k = 0; k < n_output_terms; k++) {
        const DiagramTerm *term = &DIAGRAM_OUTPUT_TERMS[k];
        model->outputs[term->to] += term->gain * source_value(model, r, term);
    }
    size_t refused = not_finite(model);
    for (size_t i = 0; i < n_outputs && refused == n_blocks; i++)
        if (!isfinite(model->outputs[i])) refused = n_blocks + 1;
    return refused;
}

/* one sample of the diagram from t over h (s): its next state and outputs taken where every value is
 * finite, else fmi2Error with both as they were */
static fmi2Status sample(Fmi2Instance *instance, Model *model, double t, double h)
{
    fmi2Real *r = instance->reals;
    char a[FLOAT_REPR_SIZE], name[64];
    size_t refused = evaluate(model, r);
    if (refused != n_blocks) {
        if (refused < n_blocks) block_name(&DIAGRAM_BLOCKS[refused], name);
        fmi2_log(instance, fmi2Error, "t=%g: a step of %s s leaves %s%s not finite; the diagram's state and outputs "
                 "held", t, float_repr(h, a), refused < n_blocks ? "the outputs or the next state of block " :
                 "the diagram's outputs", refused < n_blocks ? name : "");
        return fmi2Error;
    }
    for (size_t i = 0; i < n_states; i++) model->x[i] = model->next[i];
    for (size_t i = 0; i < n_outputs; i++) r[DIAGRAM_OUTPUT0 + i] = model->outputs[i];
    return fmi2OK;
}

/* before the first step: the outputs of sample 0, at the initial state (DIAGRAM_X0) and the inputs as they are,
 * the state left as it is (the first step gives them again); where they are not finite, as they were */
static void start(Fmi2Instance *instance)
{
    Model *model = instance->state;
    if (evaluate(model, instance->reals) != n_blocks) return;
    for (size_t i = 0; i < n_outputs; i++) instance->reals[DIAGRAM_OUTPUT0 + i] = model->outputs[i];
}

static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h)
{
    Model *model = instance->state;
    fmi2Real *r = instance->reals;
    char a[FLOAT_REPR_SIZE], b2[FLOAT_REPR_SIZE];
    if (DIAGRAM_DT == 0.0) return hold(instance, model, h) ? fmi2Error : sample(instance, model, t, h);
    const double n = grid_samples(instance->start_time, DIAGRAM_DT, t, h);
    if (n > GRID_MAX_SAMPLES) {
        fmi2_log(instance, fmi2Error, "a step of %s s from t=%g reaches %.0f samples of the diagram's sample time %s s; "
                 "one step runs %.0f at most: its state and outputs held", float_repr(h, a), t, n,
                 float_repr(DIAGRAM_DT, b2), GRID_MAX_SAMPLES);
        return fmi2Error;
    }
    double x[AT_LEAST_1(DIAGRAM_N_STATES)], y[AT_LEAST_1(DIAGRAM_N_OUTPUTS)] = {0.0}; /* what a refused sample
                                                                                          leaves */
    memcpy(x, model->x, sizeof x);
    for (size_t i = 0; i < n_outputs; i++) y[i] = r[DIAGRAM_OUTPUT0 + i];
    const double first = grid_before(instance->start_time, DIAGRAM_DT, t); /* the sample before */
    for (double k = 0.0; k < n; k++)
        if (sample(instance, model, first + k * DIAGRAM_DT, DIAGRAM_DT) != fmi2OK) {
            memcpy(model->x, x, sizeof x);
            for (size_t i = 0; i < n_outputs; i++) r[DIAGRAM_OUTPUT0 + i] = y[i];
            return fmi2Error;
        }
    return fmi2OK;
}

static int validate(const void *state, const void *configured, char *message, size_t size)
{
    const Model *model = state, *own = configured;
    char reason[MESSAGE_SIZE], name[64], a[FLOAT_REPR_SIZE];
    if (model->noted_step != 0 && model->noted_step != 1)
        return refuse(message, size, "the flag 'noted_step' is %d, not 0 or 1", model->noted_step);
    if (memcmp(model->coef, own->coef, sizeof own->coef) != 0)
        return refuse(message, size, "the diagram's blocks are not configured as its parameters configure them");
    if (model->h == 0.0) {
        if (memcmp(model->lti, own->lti, sizeof own->lti) != 0)
            return refuse(message, size, "the LTI blocks' matrices are not those of the diagram's parameters");
    } else {
        double pool[AT_LEAST_1(DIAGRAM_LTI_DOUBLES)], work[AT_LEAST_1(HOLD_WORK)];
        if (!(DIAGRAM_DT == 0.0 && isfinite(model->h) && model->h > 0.0))
            return refuse(message, size, "the step the continuous blocks are held over is %s s, not 0 (none yet)%s",
                          float_repr(model->h, a), DIAGRAM_DT == 0.0 ? " or a finite positive number" : "");
        memcpy(pool, own->lti, sizeof pool);
        if (hold_pool(own->coef, pool, model->h, work) < n_blocks ||
            memcmp(model->lti, pool, sizeof pool) != 0)
            return refuse(message, size, "the continuous blocks' matrices are not theirs held over %s s",
                          float_repr(model->h, a));
    }
    for (size_t b = 0; b < n_blocks; b++) {
        const DiagramBlock *block = &DIAGRAM_BLOCKS[b];
        if (kind_validate(block, &own->coef[b], model->x + block->state, reason, sizeof reason))
            return refuse(message, size, "block %s (%s): %s", block_name(block, name), kind_name(block->kind), reason);
    }
    return 0;
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, sizeof(Model), initialise, step, validate, start,
};
