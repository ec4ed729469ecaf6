/* params.c: Python twin blocks/params.py (resolve_params, Param.range_text, _unit), with the same
 * refusals and messages. */
#include "params.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "messages.h"

const AfStageParam *stage_param(int stage, int index)
{
    int i;
    for (i = 0; i < AF_STAGES[stage].n_params; i++)
        if (AF_STAGES[stage].params[i].index == index) return &AF_STAGES[stage].params[i];
    return NULL;
}

/* _unit: the unit as messages append it ("" for "1", else " <unit>") */
static const char *unit_text(const AfStageParam *p)
{
    return strcmp(p->unit, "1") == 0 ? "" : p->unit;
}

const char *range_text(const AfStageParam *p, char *out, size_t size)
{
    char low[FLOAT_REPR_SIZE] = "0";
    if (!(p->allow_zero || p->low == 0)) snprintf(low, sizeof low, "%g", p->low);
    snprintf(out, size, "%s%s, %g]%s%s", p->allow_zero || p->low > 0 ? "[" : "(", low, p->high,
             *unit_text(p) ? " " : "", unit_text(p));
    return out;
}

/* a value of the parameter p refused as resolve_params refuses it (0: taken) */
static int check_value(const AfStageParam *p, double v, char *message, size_t size)
{
    char value[FLOAT_REPR_SIZE], range[RANGE_TEXT_SIZE], choices[256] = "";
    int i, chosen = 0;
    if (!(isfinite(v) && (p->allow_zero ? v >= 0 : v > 0)))
        return refuse(message, size, "parameter %s must be a finite %s number (%s), got %s", p->name,
                      p->allow_zero ? "non-negative" : "positive", range_text(p, range, sizeof range),
                      float_repr(v, value));
    for (i = 0; p->choices != NULL && i < p->n_choices; i++) {
        chosen |= v == p->choices[i];
        snprintf(choices + strlen(choices), sizeof choices - strlen(choices), "%s%g", i ? " or " : "", p->choices[i]);
    }
    if (p->choices != NULL && !chosen)
        return refuse(message, size, "parameter %s must be %s, got %s (%s)", p->name, choices, float_repr(v, value),
                      p->doc);
    if (!(p->low <= v && v <= p->high))
        return refuse(message, size, "parameter %s = %g%s%s is outside its plausible range %s (%s)", p->name, v,
                      *unit_text(p) ? " " : "", unit_text(p), range_text(p, range, sizeof range), p->doc);
    return 0;
}

int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size)
{
    const AfStage *s = &AF_STAGES[stage];
    char name[64], known[1024] = "";
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
        if (check_value(p, v, message, size)) return -1;
        resolved[p->index] = v;
    }
    return 0;
}
