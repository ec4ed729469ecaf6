/* profile_params.c: the check of the motion profiles' parameters against their plausible ranges. */
#include "profile_params.h"

#include <string.h>

#include "messages.h"

const SimProfile *profile_named(const char *name) {
    for (int k = 0; k < SIM_N_PROFILES; k++)
        if (strcmp(SIM_PROFILES[k].name, name) == 0) return &SIM_PROFILES[k];
    return NULL;
}

/* value within p's range: 0, or -1 with the refusal, naming it prefix p->name */
static int check_one(const char *prefix, const SimProfileParam *p, double value, char *message, size_t size) {
    if (p->low <= value && value <= p->high) return 0;
    char repr[FLOAT_REPR_SIZE];
    const char *unit = strcmp(p->unit, "1") == 0 ? "" : p->unit;
    return refuse(message, size, "parameter %s%s = %s%s%s is outside its plausible range [%g, %g]%s%s", prefix,
                  p->name, float_repr(value, repr), *unit ? " " : "", unit, p->low, p->high, *unit ? " " : "",
                  unit);
}

int profile_check(const SimProfile *profile, const double *values, size_t n, double g, char *message,
                  size_t size) {
    if (n != (size_t)profile->n_params)
        return refuse(message, size, "profile %s takes %d parameters, got %lu", profile->name, profile->n_params,
                      (unsigned long)n);
    char prefix[32];
    size_t length = strlen(profile->name);
    if (length + 2 > sizeof prefix) return refuse(message, size, "profile name %s too long", profile->name);
    memcpy(prefix, profile->name, length);
    prefix[length] = '_', prefix[length + 1] = '\0';
    for (size_t i = 0; i < n; i++)
        if (check_one(prefix, &profile->params[i], values[i], message, size) != 0) return -1;
    return check_one("", SIM_PROFILE_GRAVITY, g, message, size);
}
