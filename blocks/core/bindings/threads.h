// threads.h: the causal pipeline over a recording on one thread or two (the batch path's run).
#ifndef AF_BINDINGS_THREADS_H
#define AF_BINDINGS_THREADS_H

#include <cstddef>
#include <functional>

extern "C" {
#include "pipeline/causal.h"
}

// fewer rows than this run on one thread unless two are asked for (starting a thread costs more
// than it gains on them)
constexpr size_t THREADED_ROWS = 20000;

// the CPUs this process may run on (its affinity on Linux, else the hardware's threads)
unsigned cpus();

// A choice of the method's (and the heading's) coefficients made before the method's first row:
// called once with the step to change and the threads it may use (1 where the run goes on beside
// it), it changes the step's method and heading coefficients alone (the gyro offset's and the
// sample time stay). It may throw; the run then stops and the exception goes on to the caller.
using Choice = std::function<void(AfStep &step, int threads)>;

// causal_run_rows over the n rows of in into out, on one thread or two: at most `threads` (0: two
// from THREADED_ROWS rows on where the process may run on two CPUs or more), and one where the
// configuration does not split (neither gyro offset nor heading runs). With two, one thread runs
// the first stages over a chunk of rows while the other runs the rest over the chunks before it,
// the stages' cost balanced between them (without heading: timing and gyro offset | method and
// latency; with heading: up to the method | heading and latency); the outputs are bit for bit
// those of one thread. choose (may be empty): the choice, made first on one thread; on two, by the
// second while the first runs the timing and gyro-offset stages ahead (the method waits for it).
// No Python object is touched but by choose: run it without the GIL.
void pipelined_run(const AfPipeline &pipeline, const AfStep &step, AfState &state, size_t n, const AfInputs &in,
                   const AfRows &out, int threads, const Choice &choose = Choice());

#endif
