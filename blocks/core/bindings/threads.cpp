// threads.cpp: the causal pipeline over a recording on one thread or two (see threads.h).
#include "threads.h"

#include <algorithm>
#include <atomic>
#include <exception>
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
constexpr size_t CHOICE_ROWS = 256 * PUBLISH_ROWS;  // the same while a choice is made (12.6 MB of rows)
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

// until test() holds or stop is set: whether it held
template <typename Test> bool wait_until(const Test &test, const std::atomic<bool> &stop)
{
    for (int spins = 0; !test(); spins++) {
        if (stop.load(std::memory_order_acquire)) return false;
        if (spins < SPINS)
            relax();
        else
            std::this_thread::yield();
    }
    return true;
}

// a state of its own for each thread, on cache lines of its own
struct alignas(64) ThreadState {
    AfState state;
};

// a run on two threads: the stages before split on the first, the rest on the second
struct Pipelined {
    const AfPipeline &pipeline;
    const AfStep &step; // the first thread's: timing and gyro offset
    AfStep chosen;      // the method's and those after it (step but for a choice)
    size_t n;
    const AfInputs &in;
    const AfRows &out;
    int starts;
    size_t handover_rows;
    std::vector<double> gyr, acc; // the hand-over, row i at i % handover_rows
    Progress first, second;
    std::atomic<bool> ready{true}, stop{false}; // the choice made; the run given up

    Pipelined(const AfPipeline &pipeline, const AfStep &step, size_t n, const AfInputs &in, const AfRows &out,
              int starts, bool choosing)
        : pipeline(pipeline), step(step), chosen(step), n(n), in(in), out(out), starts(starts),
          handover_rows(std::min(choosing ? CHOICE_ROWS : HANDOVER_ROWS, (n + CHUNK - 1) / CHUNK * CHUNK)),
          gyr(3 * handover_rows), acc(3 * handover_rows), ready(!choosing)
    {
    }

    AfHandover handover(size_t i)
    {
        size_t slot = 3 * (i % handover_rows);
        return {gyr.data() + slot, acc.data() + slot};
    }

    // stages [s0, s1) of rows [i, j) on state, with the chosen step from the method on
    void run(AfState &state, int s0, int s1, size_t i, size_t j)
    {
        const AfHandover h = handover(i);
        int start = starts && i == 0;
        if (s0 < CAUSAL_METHOD)
            causal_run_stages(&pipeline, &step, &state, s0, std::min(s1, int(CAUSAL_METHOD)), i, j, start, &in, &h,
                              &out);
        if (s1 > CAUSAL_METHOD)
            causal_run_stages(&pipeline, &chosen, &state, std::max(s0, int(CAUSAL_METHOD)), s1, i, j, start, &in, &h,
                              &out);
    }

    // this thread's progress to j, published every PUBLISH_ROWS rows and at the end
    void publish(Progress &done, size_t j)
    {
        if (j % PUBLISH_ROWS == 0 || j == n) done.rows.store(j, std::memory_order_release);
    }

    // the method's rows from behind to i, run ahead through the stages before it, through [METHOD, s1)
    void catch_up(AfState &state, int s1, Progress &done, size_t &behind, size_t i)
    {
        for (; behind < i; behind = std::min(i, behind + CHUNK)) {
            run(state, CAUSAL_METHOD, s1, behind, std::min(i, behind + CHUNK));
            publish(done, std::min(i, behind + CHUNK));
        }
    }

    // stages [s0, s1) over the rows a chunk at a time on state, each chunk once the other thread's
    // progress plus lead covers it, this thread's progress published in done. Where the method is
    // among them and the choice not yet made, the stages before it run ahead (within the
    // hand-over) and the method catches up once it is.
    void stages(AfState &state, int s0, int s1, Progress &done, const Progress &other, size_t lead)
    {
        bool waits = s0 <= CAUSAL_METHOD && CAUSAL_METHOD < s1;
        size_t seen = 0, behind = 0; // the other thread's progress; the rows the method has done
        auto chosen_and_behind = [&](size_t i) { return waits && behind < i && ready.load(std::memory_order_acquire); };
        for (size_t i = 0; i < n; i += CHUNK) {
            size_t j = std::min(n, i + CHUNK);
            while (seen + lead < j) {
                if (chosen_and_behind(i)) catch_up(state, s1, done, behind, i);
                if (!wait_until([&] { return (seen = other.rows.load(std::memory_order_acquire)) + lead >= j ||
                                             chosen_and_behind(i); }, stop))
                    return;
            }
            if (!waits || ready.load(std::memory_order_acquire)) {
                catch_up(state, s1, done, behind, i);
                run(state, s0, s1, i, j);
                publish(done, behind = j);
            } else {
                run(state, s0, CAUSAL_METHOD, i, j);
            }
        }
        if (behind < n && wait_until([&] { return ready.load(std::memory_order_acquire); }, stop))
            catch_up(state, s1, done, behind, n);
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
                   const AfRows &out, int threads, const Choice &choose)
{
    int split = split_stage(pipeline);
    bool two = split != 0 && (threads == 0 ? n >= THREADED_ROWS && cpus() >= 2 : threads >= 2);
    if (!two) {
        AfStep chosen = step;
        if (choose) choose(chosen, threads == 0 ? static_cast<int>(cpus()) : threads);
        causal_run_rows(&pipeline, &chosen, &state, n, in.gyr, in.acc, in.mag, in.initial_gravity, &out);
        return;
    }
    Pipelined run(pipeline, step, n, in, out, !state.started, static_cast<bool>(choose));
    ThreadState early{state}, late{state}; // the stages' state copied to each thread's and back
    std::thread first;
    try {
        // the first thread leads the second by at most the hand-over's rows
        first = std::thread([&run, &early, split] {
            run.stages(early.state, CAUSAL_TIMING, split, run.first, run.second, run.handover_rows);
        });
    } catch (const std::system_error &) { // no thread to be had: one does it all
        AfStep chosen = step;
        if (choose) choose(chosen, 1);
        causal_run_rows(&pipeline, &chosen, &state, n, in.gyr, in.acc, in.mag, in.initial_gravity, &out);
        return;
    }
    std::exception_ptr failed;
    try {
        if (choose) {
            choose(run.chosen, 1);
            run.ready.store(true, std::memory_order_release);
        }
        run.stages(late.state, split, CAUSAL_STAGES, run.second, run.first, 0);
    } catch (...) {
        failed = std::current_exception();
        run.stop.store(true, std::memory_order_release);
    }
    first.join();
    if (failed) std::rethrow_exception(failed);
    causal_copy_stages(&state, &early.state, CAUSAL_TIMING, split);
    causal_copy_stages(&state, &late.state, split, CAUSAL_STAGES);
}
