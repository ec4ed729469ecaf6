/* MotionProfile.c: the model of the native MotionProfile.fmu: its variables (MotionProfile_variables.h,
 * generated from systems/fmi/interface/simulation_variables.py) onto the simulation's motions: the human motion's
 * stream on its grid (human_motion.h) and the closed forms (closed_form.h), both functions of time
 * alone. doStep(t, h) outputs the interval (t, t+h]: the rate that turns the orientation over it, the
 * specific force of its mean acceleration, field and orientation at t+h; before the first step (in
 * Initialization Mode and after it) the outputs are the motion's at the start time, that instant's rate and
 * specific force, which a Jacobi master hands on before any step. A profile's parameters are the
 * Real parameters named <profile>_<parameter>, in the order of systems/simulation/profile_table.py,
 * checked against their plausible ranges at initialisation (profile_params.h).
 * The pythonfmu MotionProfile (fmu_src/MotionProfile.py) runs the same C core with the same checks,
 * messages and statuses. */
#include <math.h>
#include <string.h>

#include "MotionProfile_variables.h"
#include "messages.h"
#include "closed_form.h"
#include "earth_field.h"
#include "human_motion.h"
#include "noise.h"
#include "profile_params.h"

#define MESSAGE_SIZE 1024
#define HUMAN "human" /* the human motion's profile name; the others are closed forms */

typedef struct {
    int human; /* the human motion's stream, else the closed form */
    HumanStream stream;
    ClosedForm closed;
} Model;

/* the values of the profile's parameters, in the table's order, and their count: 0, or -1 with the
 * refusal logged */
static int profile_values(Fmi2Instance *instance, const char *profile, double values[SIM_PROFILE_MAX_PARAMS],
                          size_t *n) {
    size_t prefix = strlen(profile);
    *n = 0;
    for (size_t vr = 0; vr < N_VARIABLES; vr++) {
        const Fmi2Variable *v = &MODEL_VARIABLES[vr];
        if (v->type != FMI2_REAL || v->causality != FMI2_PARAMETER || strncmp(v->name, profile, prefix) != 0 ||
            v->name[prefix] != '_')
            continue;
        if (*n == SIM_PROFILE_MAX_PARAMS) {
            fmi2_log(instance, fmi2Error, "profile %s has more parameters than sim_profiles.h holds", profile);
            return -1;
        }
        values[(*n)++] = instance->reals[v->index];
    }
    return 0;
}

static fmi2Status initialise(Fmi2Instance *instance) {
    Model *model = instance->state;
    const char *name = fmi2_item(instance, INTEGER_profile);
    if (!name) return fmi2Error;
    char message[MESSAGE_SIZE], repr[FMI2_STRING_SIZE + 8];
    int profile = closed_form_profile(name), human = strcmp(name, HUMAN) == 0;
    if (profile < 0 && !human) {
        char available[256] = HUMAN; /* in the order of systems/simulation/profile_table.py */
        for (int k = 0; k < N_CLOSED_FORMS; k++) {
            strncat(available, ", ", sizeof available - strlen(available) - 1);
            strncat(available, CLOSED_FORM_NAMES[k], sizeof available - strlen(available) - 1);
        }
        fmi2_log(instance, fmi2Error, "invalid parameter: unknown profile %s; available: %s",
                 str_repr(name, repr, sizeof repr), available);
        return fmi2Error;
    }
    double p[SIM_PROFILE_MAX_PARAMS] = {0.0}, g = instance->reals[REAL_g];
    size_t n;
    const SimProfile *table = profile_named(name);
    if (table == NULL) {
        fmi2_log(instance, fmi2Error, "profile %s is not in sim_profiles.h", name);
        return fmi2Error;
    }
    if (profile_values(instance, name, p, &n) != 0) return fmi2Error;
    if (profile_check(table, p, n, g, message, sizeof message) != 0) {
        fmi2_log(instance, fmi2Error, "invalid parameter: %s", message);
        return fmi2Error;
    }
    model->human = human;
    if (human) {
        HumanParams params = {p[0], p[1], p[2], p[3], g, {p[5], p[6], p[7]}}; /* p[4]: the grid */
        uint64_t seed;
        if (check_seed(instance->integers[INTEGER_seed], &seed, message, sizeof message) != 0) {
            fmi2_log(instance, fmi2Error, "invalid parameter: %s", message);
            return fmi2Error;
        }
        human_stream_init(&model->stream, &params, p[4], seed);
    } else {
        model->closed.profile = (ClosedFormProfile)profile;
        memcpy(model->closed.p, p, sizeof model->closed.p);
        model->closed.g = g;
    }
    return fmi2OK;
}

static int validate(const void *state, const void *configured, char *message, size_t size) {
    const Model *model = state, *own = configured;
    if (model->human != own->human)
        return refuse(message, size, "the flag 'human' is %d, not its profile's %d", model->human, own->human);
    if (memcmp(&model->closed, &own->closed, sizeof own->closed) != 0) /* a human motion's: all 0 */
        return refuse(message, size, "the closed form is not that of its profile and parameters");
    if (!model->human) return memcmp(&model->stream, &own->stream, sizeof own->stream) == 0 ? 0 :
        refuse(message, size, "a closed form's state holds a human motion");
    return human_stream_validate(&model->stream, &own->stream, message, size);
}

/* the outputs of the interval (t, t + h] from the stream (a human motion's) or the closed form: 0, or -1 with the
 * reason in message where the human motion refuses the interval or the arithmetic leaves them not finite; h = 0:
 * the instant t */
static int motion_at(Model *model, HumanStream *stream, double t, double h, double out[HUMAN_N_OUT + 3],
                     char *message, size_t size) {
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE];
    if (model->human) {
        if (human_stream_step(stream, t, t + h, out, message, size) != 0) return -1;
    } else closed_form_at(&model->closed, t + h, h, out, out + 3, out + 6);
    earth_field_in_sensor(out + 6, out + HUMAN_N_OUT);
    for (int i = 0; i < HUMAN_N_OUT + 3; i++)
        if (!isfinite(out[i]))
            return refuse(message, size, "a step of %s s to %s s overflows the motion's arithmetic", float_repr(h, a),
                          float_repr(t + h, b));
    return 0;
}

static void write_outputs(fmi2Real *r, const double out[HUMAN_N_OUT + 3]) {
    for (int i = 0; i < 3; i++) r[REAL_omega_x + i] = out[i], r[REAL_f_x + i] = out[3 + i];
    for (int i = 0; i < 4; i++) r[REAL_qt_w + i] = out[6 + i];
    for (int i = 0; i < 3; i++) r[REAL_m_x + i] = out[HUMAN_N_OUT + i];
}

/* the outputs of the interval (t, t + h]; where the step's arithmetic leaves them not finite, or the human
 * motion refuses the step, fmi2Error with the reason and the outputs and the stream as they were */
static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h) {
    Model *model = instance->state;
    double out[HUMAN_N_OUT + 3];
    char message[MESSAGE_SIZE];
    HumanStream next = model->stream;
    if (motion_at(model, &next, t, h, out, message, sizeof message) != 0) {
        fmi2_log(instance, fmi2Error, "%s", message);
        return fmi2Error;
    }
    model->stream = next;
    write_outputs(instance->reals, out);
    return fmi2OK;
}

/* the motion at the start time: the rate and specific force at that instant (a step of 0 s), on a copy of the
 * stream; where its arithmetic fails, the outputs as they were (the first step says why) */
static void start(Fmi2Instance *instance) {
    Model *model = instance->state;
    double out[HUMAN_N_OUT + 3];
    char message[MESSAGE_SIZE];
    HumanStream copy = model->stream;
    if (motion_at(model, &copy, instance->start_time, 0.0, out, message, sizeof message) == 0)
        write_outputs(instance->reals, out);
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, sizeof(Model), initialise, step, validate, start,
};
