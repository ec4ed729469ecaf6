/* params.c: the tuning parameters' validation (see params.h), worded as the package's messages. */
#include "params.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "messages.h"

int param_index(const char *name)
{
    for (int i = 0; name != NULL && i < AF_N_PARAMS; i++)
        if (strcmp(AF_PARAMS[i].name, name) == 0) return i;
    return -1;
}

const AfStageParam *stage_param(int stage, int index)
{
    for (int i = 0; i < AF_STAGES[stage].n_params; i++)
        if (AF_STAGES[stage].params[i].index == index) return &AF_STAGES[stage].params[i];
    return NULL;
}

const AfStageParam *stage_param_named(int stage, const char *name)
{
    int index = param_index(name);
    return index < 0 ? NULL : stage_param(stage, index);
}

int given_values(const double values[AF_N_PARAMS], AfGiven given[AF_N_PARAMS])
{
    int n = 0;
    for (int i = 0; i < AF_N_PARAMS; i++)
        if (!isnan(values[i])) given[n++] = (AfGiven){AF_PARAMS[i].name, values[i], NULL};
    return n;
}

/* the unit as messages append it ("" for "1", else " <unit>") */
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

/* a given value of the parameter p refused (-1, with the message) or taken (0) */
static int check_value(const AfStageParam *p, const AfGiven *given, char *message, size_t size)
{
    char value[FLOAT_REPR_SIZE], range[RANGE_TEXT_SIZE], choices[256] = "";
    const char *shown = given->shown != NULL ? given->shown : float_repr(given->value, value);
    double v = given->value;
    int chosen = 0;
    if (!(isfinite(v) && (p->allow_zero ? v >= 0 : v > 0)))
        return refuse(message, size, "parameter %s must be a finite %s number (%s), got %s", p->name,
                      p->allow_zero ? "non-negative" : "positive", range_text(p, range, sizeof range), shown);
    for (int i = 0; p->choices != NULL && i < p->n_choices; i++) {
        chosen |= v == p->choices[i];
        snprintf(choices + strlen(choices), sizeof choices - strlen(choices), "%s%g", i ? " or " : "", p->choices[i]);
    }
    if (p->choices != NULL && !chosen)
        return refuse(message, size, "parameter %s must be %s, got %s (%s)", p->name, choices, shown, p->doc);
    if (!(p->low <= v && v <= p->high))
        return refuse(message, size, "parameter %s = %g%s%s is outside its plausible range %s (%s)", p->name, v,
                      *unit_text(p) ? " " : "", unit_text(p), range_text(p, range, sizeof range), p->doc);
    return 0;
}

int resolve_given(int stage, const AfGiven *given, int n, double resolved[AF_N_PARAMS], char *message, size_t size)
{
    const AfStage *s = &AF_STAGES[stage];
    for (int i = 0; i < AF_N_PARAMS; i++) resolved[i] = NAN;
    for (int i = 0; i < s->n_params; i++) resolved[s->params[i].index] = s->params[i].default_value;
    for (int k = 0; k < n; k++) {
        const AfStageParam *p = stage_param_named(stage, given[k].name);
        if (p == NULL) {
            char name[64], known[1024] = "";
            for (int j = 0; j < s->n_params; j++) {
                if (j > 0) strncat(known, ", ", sizeof known - strlen(known) - 1);
                strncat(known, s->params[j].name, sizeof known - strlen(known) - 1);
            }
            return refuse(message, size, "unknown parameter %s for %s; known: %s",
                          str_repr(given[k].name, name, sizeof name), s->owner, known);
        }
        if (check_value(p, &given[k], message, size)) return -1;
        resolved[p->index] = given[k].value;
    }
    return 0;
}

int resolve_params(int stage, const double given[AF_N_PARAMS], double resolved[AF_N_PARAMS], char *message,
                   size_t size)
{
    AfGiven list[AF_N_PARAMS];
    return resolve_given(stage, list, given_values(given, list), resolved, message, size);
}
