/* MotionProfile.c: the model of the native MotionProfile.fmu: its variables (MotionProfile_variables.h,
 * generated from fmu_src/simulation_variables.py) onto the simulation's motions: the human motion's
 * stream (human_motion.h) and the closed forms (closed_form.h). doStep(t, h) outputs the
 * interval (t, t+h]. A profile's parameters are the Real parameters named <profile>_<parameter>, in
 * the order of systems/simulation/profile_table.py.
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

#define MESSAGE_SIZE 1024
#define HUMAN "human" /* the human motion's profile name; the others are closed forms */

typedef struct {
    int human; /* the human motion's stream, else the closed form */
    HumanStream stream;
    ClosedForm closed;
} Model;

/* the values of the profile's parameters, in the table's order: 0, or -1 with the refusal logged */
static int profile_values(Fmi2Instance *instance, const char *profile, double values[CLOSED_FORM_MAX_PARAMS]) {
    size_t prefix = strlen(profile), n = 0;
    for (size_t vr = 0; vr < N_VARIABLES; vr++) {
        const Fmi2Variable *v = &MODEL_VARIABLES[vr];
        if (v->type != FMI2_REAL || v->causality != FMI2_PARAMETER || strncmp(v->name, profile, prefix) != 0 ||
            v->name[prefix] != '_')
            continue;
        double value = instance->reals[v->index];
        if (!isfinite(value)) {
            char repr[FLOAT_REPR_SIZE];
            fmi2_log(instance, fmi2Error, "invalid parameter: parameter %s must be finite, got %s",
                     v->name + prefix + 1, float_repr(value, repr));
            return -1;
        }
        if (n == CLOSED_FORM_MAX_PARAMS) {
            fmi2_log(instance, fmi2Error, "profile %s has more parameters than closed_form.h holds", profile);
            return -1;
        }
        values[n++] = value;
    }
    return 0;
}

static fmi2Status initialise(Fmi2Instance *instance) {
    Model *model = instance->state;
    const char *name = instance->strings[STRING_profile];
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
    double p[CLOSED_FORM_MAX_PARAMS] = {0.0};
    if (profile_values(instance, name, p) != 0) return fmi2Error;
    double g = instance->reals[REAL_g];
    model->human = human;
    if (human) {
        HumanParams params = {p[0], p[1], p[2], p[3], g};
        uint64_t seed;
        if (human_check(&params, message, sizeof message) != 0 ||
            check_seed(instance->integers[INTEGER_seed], &seed, message, sizeof message) != 0) {
            fmi2_log(instance, fmi2Error, "invalid parameter: %s", message);
            return fmi2Error;
        }
        human_stream_init(&model->stream, &params, seed);
    } else {
        model->closed.profile = (ClosedFormProfile)profile;
        memcpy(model->closed.p, p, sizeof p);
        model->closed.g = g;
    }
    return fmi2OK;
}

static fmi2Status step(Fmi2Instance *instance, fmi2Real t, fmi2Real h) {
    Model *model = instance->state;
    fmi2Real *r = instance->reals;
    double out[HUMAN_N_OUT];
    if (model->human) human_stream_step(&model->stream, h, out);
    else closed_form_at(&model->closed, t + h, h, out, out + 3, out + 6);
    for (int i = 0; i < 3; i++) r[REAL_omega_x + i] = out[i], r[REAL_f_x + i] = out[3 + i];
    for (int i = 0; i < 4; i++) r[REAL_qt_w + i] = out[6 + i];
    earth_field_in_sensor(out + 6, &r[REAL_m_x]);
    return fmi2OK;
}

const Fmi2Model fmi2_model = {
    MODEL_IDENTIFIER, MODEL_GUID, MODEL_VARIABLES, N_VARIABLES, N_REALS, N_INTEGERS, N_BOOLEANS, N_STRINGS,
    MODEL_LOG_CATEGORIES, N_LOG_CATEGORIES, sizeof(Model), initialise, step,
};
