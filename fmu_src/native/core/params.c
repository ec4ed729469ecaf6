/* params.c: Python twin blocks/params.py (resolve_params), with the same refusals and messages. */
#include "params.h"

#include <math.h>
#include <string.h>

#include "messages.h"

const AfStageParam *stage_param(int stage, int index)
{
    int i;
    for (i = 0; i < AF_STAGES[stage].n_params; i++)
        if (AF_STAGES[stage].params[i].index == index) return &AF_STAGES[stage].params[i];
    return NULL;
}

int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size)
{
    const AfStage *s = &AF_STAGES[stage];
    char value[FLOAT_REPR_SIZE], name[64], known[1024] = "";
    int i;
    for (i = 0; i < AF_N_PARAMS; i++) {
        resolved[i] = NAN;
        if (isnan(given[i]) || stage_param(stage, i) != NULL) continue;
        for (int j = 0; j < s->n_params; j++) {
            if (j > 0) strncat(known, ", ", sizeof known - strlen(known) - 1);
            strncat(known, s->params[j].name, sizeof known - strlen(known) - 1);
        }
        return refuse(message, size, "unknown parameter %s for %s; known: %s",
                      str_repr(AF_PARAMS[i].name, name, sizeof name), s->owner, known);
    }
    /* in the stage's order, as blocks.pipeline.causal.split_params hands the values over */
    for (i = 0; i < s->n_params; i++) {
        const AfStageParam *p = &s->params[i];
        double v = given[p->index];
        if (isnan(v)) {
            resolved[p->index] = p->default_value;
            continue;
        }
        if (!(isfinite(v) && (p->allow_zero ? v >= 0 : v > 0)))
            return refuse(message, size, "parameter %s must be a finite %s number, got %s", p->name,
                          p->allow_zero ? "non-negative" : "positive", float_repr(v, value));
        resolved[p->index] = v;
    }
    return 0;
}
