/* delay_line.c: Python twin systems/simulation/sensor_model.py (ImuModel.delay_state, delay_step);
 * the rows of the Python state are the ring's, newest first. */
#include "sim/delay_line.h"

#include <math.h>

#include "messages.h"

int delay_init(DelayLine *line, double latency, double fs, const double before[DELAY_WIDTH], char *message,
               size_t size) {
    double samples = floor(latency * fs);
    if (!(samples < DELAY_MAX_ROWS - 2)) {
        char a[FLOAT_REPR_SIZE], b[FLOAT_REPR_SIZE];
        return refuse(message, size, "latency %s s at %s Hz is longer than the delay line's %d samples",
                      float_repr(latency, a), float_repr(fs, b), DELAY_MAX_ROWS - 3);
    }
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
