/* delay_line.h: the IMU's latency, the true (omega, f) it measures that long ago. Both are means
 * over the sample time, constant within each: the mean over an interval latency = (m + phi)/fs
 * earlier is (1 - phi) x[k - m] + phi x[k - m - 1]. Before the first sample the motion is taken
 * as given (the first sample's in the FMU). Bound into Python by systems/simulation/sensor_model.py
 * (ImuModel.delayed, delay_state, delay_step). */
#ifndef SIM_DELAY_LINE_H
#define SIM_DELAY_LINE_H

#include <stddef.h>

#define DELAY_WIDTH 6         /* omega (3), f (3) */
#define DELAY_MAX_ROWS 1024   /* the rows it holds: latency*fs below DELAY_MAX_ROWS - 2 samples */

/* a ring of the last m + 2 rows (m = floor(latency*fs)): the m + 1 past ones and the new one */
typedef struct {
    double latency, fs;
    int rows, head; /* rows in use; the newest row's place */
    double x[DELAY_MAX_ROWS][DELAY_WIDTH];
} DelayLine;

/* the line at fs (Hz) for latency (s) before the first sample, every past row equal to before:
 * 0, or -1 with a message where latency*fs is not 0 or more samples or too long for it */
int delay_init(DelayLine *line, double latency, double fs, const double before[DELAY_WIDTH], char *message,
               size_t size);
/* whether line (bytes nobody vouches for, e.g. an FMU state's) is the line delay_init makes for latency
 * (s) at fs (Hz), stepped on: its latency and fs those, its rows theirs, its head one of them, the rows in
 * use finite. 0, or -1 with a message. */
int delay_validate(const DelayLine *line, double latency, double fs, char *message, size_t size);
/* this sample's true (omega, f) in, those latency seconds ago out */
void delay_step(DelayLine *line, const double signals[DELAY_WIDTH], double out[DELAY_WIDTH]);
/* n samples: signals and out n rows of DELAY_WIDTH (they may be the same array) */
void delay_run(DelayLine *line, const double *signals, size_t n, double *out);

/* The line between samples as a flat state (a python-control block's): the rows - 1 newest rows,
 * newest first, (rows - 1) * DELAY_WIDTH numbers. delay_load takes them into a line that
 * delay_init made for the same latency and fs. */
void delay_save(const DelayLine *line, double *past);
void delay_load(DelayLine *line, const double *past);

#endif
