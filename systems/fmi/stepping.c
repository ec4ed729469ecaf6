/* stepping.c: the stepping loop of the co-simulation master systems.fmi.cosim in C: fixed steps of
 * FMI 2.0 co-simulation components in the order of their connections (Gauss-Seidel: in a step, a
 * component's inputs are the outputs its sources gave in that step), every output recorded. The
 * components are instantiated and initialised by the Python master (fmpy), which hands over each
 * instance with its library's functions. Knows nothing of what the components compute.
 * Python twin: systems/fmi/cosim.py (_python_steps, the same loop). */
#include <stddef.h>

#include "fmi2FunctionTypes.h"

/* one component; outputs are recorded into a row of doubles (Booleans as 0 or 1), at the places at */
typedef struct {
    fmi2Component instance;
    fmi2DoStepTYPE *do_step;
    fmi2SetRealTYPE *set_real;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    size_t n_inputs;
    const fmi2ValueReference *input_vr;
    const size_t *input_from; /* where each input's source output is in the row */
    size_t n_reals;
    const fmi2ValueReference *real_vr;
    size_t real_at; /* the first of its n_reals places in the row */
    size_t n_booleans;
    const fmi2ValueReference *boolean_vr;
    size_t boolean_at;
} SteppedComponent;

#define MAX_VALUES 256 /* inputs or Booleans of one component */

/* steps first ... first + n - 1 of h seconds from t0 + first * h, into rows of record (width values
 * each, row 0 the step first). Returns the number of steps done: n, or fewer where a call returned
 * a status worse than fmi2Warning (then *failed is the component and *status its status). */
size_t stepping_run(size_t n_components, const SteppedComponent *components, double t0, double h, size_t first,
                    size_t n, size_t width, double *record, size_t *failed, int *status) {
    for (size_t k = 0; k < n; k++) {
        double *row = record + k * width, t = t0 + (double)(first + k) * h;
        for (size_t c = 0; c < n_components; c++) {
            const SteppedComponent *s = &components[c];
            fmi2Real inputs[MAX_VALUES];
            fmi2Boolean booleans[MAX_VALUES];
            fmi2Status st = fmi2OK; /* a status worse than fmi2Warning ends the run, as fmpy raises on it */
            if (s->n_inputs > MAX_VALUES || s->n_booleans > MAX_VALUES) st = fmi2Fatal;
            for (size_t i = 0; st <= fmi2Warning && i < s->n_inputs; i++) inputs[i] = row[s->input_from[i]];
            if (st <= fmi2Warning && s->n_inputs) st = s->set_real(s->instance, s->input_vr, s->n_inputs, inputs);
            if (st <= fmi2Warning) st = s->do_step(s->instance, t, h, fmi2True);
            if (st <= fmi2Warning && s->n_reals) st = s->get_real(s->instance, s->real_vr, s->n_reals, row + s->real_at);
            if (st <= fmi2Warning && s->n_booleans) {
                st = s->get_boolean(s->instance, s->boolean_vr, s->n_booleans, booleans);
                for (size_t i = 0; i < s->n_booleans; i++) row[s->boolean_at + i] = booleans[i] ? 1.0 : 0.0;
            }
            if (st > fmi2Warning) {
                *failed = c;
                *status = (int)st;
                return k;
            }
        }
    }
    return n;
}
