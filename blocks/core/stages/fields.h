/* fields.h: a stage's state as a struct of doubles, declared once by a list of its fields
 * X(name, dims) (dims: [n], or empty for one value): AF_DOUBLES declares the struct's members,
 * AF_FIELD the entry of a table of the fields, which names the entries of a python-control
 * block's state vector (the struct as an array of doubles); and a check of such a struct. */
#ifndef AF_FIELDS_H
#define AF_FIELDS_H

#include <math.h>
#include <stddef.h>

/* One field of a struct of doubles: its name and number of entries (the fields in their order). */
typedef struct {
    const char *name;
    size_t count;
} AfField;

#define AF_DOUBLES(name, dims) double name dims;
#define AF_FIELD(type, name) {#name, sizeof(((type *)0)->name) / sizeof(double)},

/* whether every double of a struct of doubles (size bytes) is finite, unset (where not NULL) aside:
 * a NaN there stands for a value not given */
static inline int af_finite(const void *doubles, size_t size, const double *unset)
{
    const double *values = (const double *)doubles;
    for (size_t i = 0; i < size / sizeof(double); i++)
        if (!isfinite(values[i]) && !(&values[i] == unset && isnan(values[i])))
            return 0;
    return 1;
}

#endif
