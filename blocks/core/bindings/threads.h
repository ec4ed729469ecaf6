// threads.h: the causal pipeline over a recording on one thread or two (the batch path's run).
#ifndef AF_BINDINGS_THREADS_H
#define AF_BINDINGS_THREADS_H

#include <cstddef>

extern "C" {
#include "pipeline/causal.h"
}

// fewer rows than this run on one thread unless two are asked for (starting a thread costs more
// than it gains on them)
constexpr size_t THREADED_ROWS = 20000;

// causal_run_rows over the n rows of in into out, on one thread or two: at most `threads` (0: two
// from THREADED_ROWS rows on where the process may run on two CPUs or more), and one where the
// configuration does not split (neither gyro offset nor heading runs). With two, one thread runs
// the first stages over a chunk of rows while the other runs the rest over the chunks before it,
// the stages' cost balanced between them (without heading: timing and gyro offset | method and
// latency; with heading: up to the method | heading and latency); the outputs are bit for bit
// those of one thread. No Python object is touched: run it without the GIL.
// the CPUs this process may run on (its affinity on Linux, else the hardware's threads)
unsigned cpus();

void pipelined_run(const AfPipeline &pipeline, const AfStep &step, AfState &state, size_t n, const AfInputs &in,
                   const AfRows &out, int threads);

#endif
