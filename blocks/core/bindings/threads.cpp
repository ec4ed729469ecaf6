// threads.cpp: the causal pipeline over a recording on one thread or two (see threads.h).
#include "threads.h"

#include <algorithm>
#include <atomic>
#include <system_error>
#include <thread>
#include <vector>

#ifdef __linux__
#include <sched.h>
#endif

namespace {

constexpr size_t CHUNK = CAUSAL_CHUNK;              // rows a thread runs its stages over in turn
constexpr size_t PUBLISH_ROWS = 16 * CHUNK;         // rows between two stores of a thread's progress
constexpr size_t HANDOVER_ROWS = 4 * PUBLISH_ROWS;  // the hand-over's rows: how far the first thread may lead
constexpr int SPINS = 2000;                         // pauses of a waiting thread before it yields its CPU

// the stage from which the second thread takes the rows over; 0: the configuration does not split
int split_stage(const AfPipeline &pipeline)
{
    if (pipeline.heading_runs) return CAUSAL_HEADING;
    if (pipeline.offset_runs) return CAUSAL_METHOD;
    return 0;
}


// the rows a thread has done, on a cache line of its own
struct alignas(64) Progress {
    std::atomic<size_t> rows{0};
};

// a spinning thread's hint to the CPU (x86's pause: the resources it shares go to the other thread)
inline void relax()
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_ia32_pause();
#endif
}

// the other thread's progress, once it has done rows
size_t wait_for(const Progress &other, size_t rows)
{
    size_t seen;
    for (int spins = 0; (seen = other.rows.load(std::memory_order_acquire)) < rows; spins++)
        if (spins < SPINS)
            relax();
        else
            std::this_thread::yield();
    return seen;
}

// a state of its own for each thread, on cache lines of its own
struct alignas(64) ThreadState {
    AfState state;
};

// a run on two threads: the stages before split on the first, the rest on the second
struct Pipelined {
    const AfPipeline &pipeline;
    const AfStep &step;
    size_t n;
    const AfInputs &in;
    const AfRows &out;
    int starts;
    std::vector<double> gyr, acc; // the hand-over of HANDOVER_ROWS rows, row i at i % HANDOVER_ROWS
    Progress first, second;

    Pipelined(const AfPipeline &pipeline, const AfStep &step, size_t n, const AfInputs &in, const AfRows &out,
              int starts)
        : pipeline(pipeline), step(step), n(n), in(in), out(out), starts(starts), gyr(3 * HANDOVER_ROWS),
          acc(3 * HANDOVER_ROWS)
    {
    }

    // stages [s0, s1) over the rows a chunk at a time on state, each chunk once the other thread's
    // progress plus lead covers it, this thread's progress published in done
    void stages(AfState &state, int s0, int s1, Progress &done, const Progress &other, size_t lead)
    {
        size_t seen = 0;
        for (size_t i = 0; i < n; i += CHUNK) {
            size_t j = std::min(n, i + CHUNK), slot = 3 * (i % HANDOVER_ROWS);
            if (seen + lead < j) seen = wait_for(other, j - lead);
            const AfHandover handover = {gyr.data() + slot, acc.data() + slot};
            causal_run_stages(&pipeline, &step, &state, s0, s1, i, j, starts && i == 0, &in, &handover, &out);
            if (j % PUBLISH_ROWS == 0 || j == n) done.rows.store(j, std::memory_order_release);
        }
    }
};

} // namespace

unsigned cpus()
{
#ifdef __linux__
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0) return static_cast<unsigned>(CPU_COUNT(&set));
#endif
    return std::thread::hardware_concurrency();
}

void pipelined_run(const AfPipeline &pipeline, const AfStep &step, AfState &state, size_t n, const AfInputs &in,
                   const AfRows &out, int threads)
{
    int split = split_stage(pipeline);
    bool two = split != 0 && (threads == 0 ? n >= THREADED_ROWS && cpus() >= 2 : threads >= 2);
    if (!two) {
        causal_run_rows(&pipeline, &step, &state, n, in.gyr, in.acc, in.mag, in.initial_gravity, &out);
        return;
    }
    Pipelined run(pipeline, step, n, in, out, !state.started);
    ThreadState early{state}, late{state}; // the stages' state copied to each thread's and back
    std::thread first;
    try {
        // the first thread leads the second by at most the hand-over's rows
        first = std::thread([&run, &early, split] {
            run.stages(early.state, CAUSAL_TIMING, split, run.first, run.second, HANDOVER_ROWS);
        });
    } catch (const std::system_error &) { // no thread to be had: one does it all
        causal_run_rows(&pipeline, &step, &state, n, in.gyr, in.acc, in.mag, in.initial_gravity, &out);
        return;
    }
    run.stages(late.state, split, CAUSAL_STAGES, run.second, run.first, 0);
    first.join();
    causal_copy_stages(&state, &early.state, CAUSAL_TIMING, split);
    causal_copy_stages(&state, &late.state, split, CAUSAL_STAGES);
}
