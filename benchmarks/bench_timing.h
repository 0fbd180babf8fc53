// Clocks for the benchmarks on a shared machine: process CPU time (time other processes hold the
// cores does not count), the load average printed next to every figure, a cheap tick count for
// splitting a run's time, and the median of repeated runs.
#pragma once

#include <time.h>

#if defined(__x86_64__) || defined(_M_X64)
#include <x86intrin.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <vector>

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

/// A cheap monotonic tick count for splitting a run's time (only ratios of ticks are used): the
/// time-stamp counter on x86-64 (a few ns to read), else the steady clock in ns.
inline uint64_t ticks() {
#if defined(__x86_64__) || defined(_M_X64)
    return __rdtsc();
#else
    return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch()).count());
#endif
}

/// Median of repeated measurements (0 for none).
inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace whitted::app
