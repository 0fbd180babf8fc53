// A progress bar with the elapsed time and an ETA on stderr, for long work split into steps.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>

namespace whitted {

class ProgressBar {
public:
    /// A bar over `total` steps; draws nothing unless `enabled` and stderr is a terminal.
    ProgressBar(size_t total, bool enabled);
    /// One step done (any thread); redraws at most every 200 ms, by whichever thread gets there.
    void advance();
    /// Draws the full bar and ends its line.
    void finish();

private:
    using Clock = std::chrono::steady_clock;
    void draw(size_t done, Clock::time_point now);
    size_t m_total;
    bool m_enabled;
    std::atomic<size_t> m_done{0};
    std::mutex m_mutex;
    Clock::time_point m_start = Clock::now();
    Clock::time_point m_last{};
};

}  // namespace whitted
