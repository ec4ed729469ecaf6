/* messages.h: the wording of the C core's refusals, which the Python package raises as they are:
 * values shown as Python shows them (repr of a float or a string; f"{x:g}" is printf's %g). */
#ifndef AF_MESSAGES_H
#define AF_MESSAGES_H

#include <stddef.h>

#define FLOAT_REPR_SIZE 32 /* bytes that hold any float_repr, its terminating 0 included */

/* Python's repr of the float x: the shortest digits that read back as x, fixed notation for
 * decimal exponents -4 ... 15 ("0.01", "100.0"), else scientific ("1e+300", "1.5e-05");
 * "inf", "-inf", "nan". Written to out and returned. */
const char *float_repr(double x, char out[FLOAT_REPR_SIZE]);

/* Python's repr of the string s ('wiener', "it's"), cut to size bytes; returns out. */
const char *str_repr(const char *s, char *out, size_t size);

/* printf into message (size bytes; nothing written where message is NULL or size 0) and
 * return -1, the status of a refusal. */
int refuse(char *message, size_t size, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif
