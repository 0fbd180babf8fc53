// Clocks for the benchmarks on a shared machine: process CPU time (time other processes hold the
// cores does not count) and the load average printed next to every figure.
#pragma once

#include <time.h>

#include <cstdlib>

namespace whitted::app {

/// CPU time of the whole process, all threads, in seconds. With one worker thread it is the work
/// a render did; with more it also counts the workers' idle spinning at the ends of parallel loops.
inline double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// CPU time of the calling thread in seconds: with work on one thread, the time it was
/// descheduled (other processes on a loaded machine) does not count.
inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// The 1-minute load average, or -1 when unavailable.
inline double load_average_1min() {
    double l[1] = {0.0};
    return getloadavg(l, 1) == 1 ? l[0] : -1.0;
}

}  // namespace whitted::app
