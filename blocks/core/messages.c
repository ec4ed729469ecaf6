/* messages.c: Python's repr of floats and strings, and refusals (see messages.h). */
#include "messages.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *float_repr(double x, char out[FLOAT_REPR_SIZE])
{
    char scientific[FLOAT_REPR_SIZE], digits[FLOAT_REPR_SIZE];
    int precision, exponent, length = 0, n = 0, i;
    const char *e;
    if (isnan(x)) return strcpy(out, "nan");
    if (isinf(x)) return strcpy(out, x > 0 ? "inf" : "-inf");
    /* the shortest scientific form that reads back as x: d.ddde±XX */
    for (precision = 0; precision < 17; precision++) {
        snprintf(scientific, sizeof scientific, "%.*e", precision, x);
        if (strtod(scientific, NULL) == x) break;
    }
    e = strchr(scientific, 'e');
    exponent = atoi(e + 1);
    for (i = 0; scientific + i < e; i++) /* the significant digits, without sign and point */
        if (scientific[i] >= '0' && scientific[i] <= '9') digits[length++] = scientific[i];
    if (signbit(x)) out[n++] = '-';
    if (exponent < -4 || exponent >= 16) { /* as Python: d.ddde-05, de+300 */
        out[n++] = digits[0];
        if (length > 1) out[n++] = '.';
        for (i = 1; i < length; i++) out[n++] = digits[i];
        snprintf(out + n, FLOAT_REPR_SIZE - n, "e%c%02d", exponent < 0 ? '-' : '+', abs(exponent));
        return out;
    }
    if (exponent < 0) { /* 0.000ddd */
        out[n++] = '0';
        out[n++] = '.';
        for (i = 0; i < -exponent - 1; i++) out[n++] = '0';
        for (i = 0; i < length; i++) out[n++] = digits[i];
    } else { /* ddd.ddd, at least one digit after the point */
        for (i = 0; i <= exponent; i++) out[n++] = i < length ? digits[i] : '0';
        out[n++] = '.';
        if (length <= exponent + 1) out[n++] = '0';
        for (i = exponent + 1; i < length; i++) out[n++] = digits[i];
    }
    out[n] = '\0';
    return out;
}

const char *str_repr(const char *s, char *out, size_t size)
{
    /* Python quotes with ' unless the string holds a ' and no " */
    char quote = strchr(s, '\'') && !strchr(s, '"') ? '"' : '\'';
    size_t n = 0;
    if (size == 0) return out;
#define PUT(text)                                                   \
    do {                                                            \
        const char *t_ = (text);                                    \
        while (*t_ && n + 1 < size) out[n++] = *t_++;               \
    } while (0)
    {
        char q[2] = {quote, '\0'};
        PUT(q);
        for (; *s; s++) {
            unsigned char c = (unsigned char)*s;
            char one[8];
            if (c == '\\') PUT("\\\\");
            else if (c == (unsigned char)quote) { one[0] = '\\'; one[1] = quote; one[2] = '\0'; PUT(one); }
            else if (c == '\n') PUT("\\n");
            else if (c == '\r') PUT("\\r");
            else if (c == '\t') PUT("\\t");
            else if (c < 32 || c == 127) { snprintf(one, sizeof one, "\\x%02x", c); PUT(one); }
            else { one[0] = (char)c; one[1] = '\0'; PUT(one); }
        }
        PUT(q);
    }
#undef PUT
    out[n] = '\0';
    return out;
}

int refuse(char *message, size_t size, const char *format, ...)
{
    if (message != NULL && size > 0) {
        va_list args;
        va_start(args, format);
        vsnprintf(message, size, format, args);
        va_end(args);
    }
    return -1;
}
