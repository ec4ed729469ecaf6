/* delay_line.c: the IMU's latency as a ring of rows. */
#include "delay_line.h"

#include <math.h>

#include "messages.h"

int delay_init(DelayLine *line, double latency, double fs, const double before[DELAY_WIDTH], char *message,
               size_t size) {
    double samples = floor(latency * fs);
    char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE];
    if (!(samples >= 0.0))
        return refuse(message, size, "latency %s s at %s Hz must be a delay of 0 or more samples",
                      float_repr(latency, a), float_repr(fs, b));
    if (!(samples < DELAY_MAX_ROWS - 2))
        return refuse(message, size, "latency %s s at %s Hz is longer than the delay line's %d samples",
                      float_repr(latency, a), float_repr(fs, b), DELAY_MAX_ROWS - 3);
    line->latency = latency, line->fs = fs;
    line->rows = (int)samples + 2;
    line->head = 0;
    for (int r = 0; r < line->rows; r++)
        for (int i = 0; i < DELAY_WIDTH; i++) line->x[r][i] = before[i];
    return 0;
}

void delay_step(DelayLine *line, const double signals[DELAY_WIDTH], double out[DELAY_WIDTH]) {
    double m = floor(line->latency * line->fs), phase = fmod(line->latency * line->fs, 1.0);
    line->head = (line->head + 1) % line->rows;
    for (int i = 0; i < DELAY_WIDTH; i++) line->x[line->head][i] = signals[i];
    const double *late = line->x[(line->head - (int)m + line->rows) % line->rows];
    const double *later = line->x[(line->head - (int)m - 1 + line->rows) % line->rows];
    for (int i = 0; i < DELAY_WIDTH; i++) out[i] = (1.0 - phase) * late[i] + phase * later[i];
}

void delay_run(DelayLine *line, const double *signals, size_t n, double *out) {
    double row[DELAY_WIDTH];
    for (size_t k = 0; k < n; k++) {
        for (int i = 0; i < DELAY_WIDTH; i++) row[i] = signals[DELAY_WIDTH * k + i];
        delay_step(line, row, out + DELAY_WIDTH * k);
    }
}

void delay_save(const DelayLine *line, double *past) {
    for (int r = 0; r < line->rows - 1; r++) {
        const double *row = line->x[(line->head - r + line->rows) % line->rows];
        for (int i = 0; i < DELAY_WIDTH; i++) past[DELAY_WIDTH * r + i] = row[i];
    }
}

void delay_load(DelayLine *line, const double *past) {
    line->head = line->rows - 2; /* the newest at rows - 2, the oldest at 0: the next step writes rows - 1 */
    for (int r = 0; r < line->rows - 1; r++)
        for (int i = 0; i < DELAY_WIDTH; i++) line->x[line->head - r][i] = past[DELAY_WIDTH * r + i];
}

int delay_validate(const DelayLine *line, double latency, double fs, char *message, size_t size) {
    double samples = floor(latency * fs);
    if (!(samples >= 0.0 && samples < DELAY_MAX_ROWS - 2) || line->latency != latency || line->fs != fs)
        return refuse(message, size, "the delay line is not one for its latency and sample rate");
    if (line->rows != (int)samples + 2 || line->head < 0 || line->head >= line->rows)
        return refuse(message, size, "the delay line's rows (%d) or head (%d) are out of their range", line->rows,
                      line->head);
    for (int r = 0; r < line->rows; r++)
        for (int i = 0; i < DELAY_WIDTH; i++)
            if (!isfinite(line->x[r][i])) return refuse(message, size, "the delay line holds values not finite");
    return 0;
}
