#include "core/progress.h"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace whitted {

ProgressBar::ProgressBar(size_t total, bool enabled) : m_total(total), m_enabled(enabled && isatty(STDERR_FILENO)) {}

void ProgressBar::advance() {
    const size_t done = ++m_done;
    if (!m_enabled) return;
    std::unique_lock lock(m_mutex, std::try_to_lock);
    if (!lock.owns_lock()) return;
    const auto now = Clock::now();
    if (done != m_total && now - m_last < std::chrono::milliseconds(200)) return;
    m_last = now;
    draw(done, now);
}

void ProgressBar::finish() {
    if (!m_enabled) return;
    std::lock_guard lock(m_mutex);
    draw(m_total, Clock::now());
    std::fputc('\n', stderr);
}

void ProgressBar::draw(size_t done, Clock::time_point now) {
    const double f = m_total ? double(done) / double(m_total) : 1.0;
    const double elapsed = std::chrono::duration<double>(now - m_start).count();
    const double eta = f > 0 ? elapsed * (1.0 - f) / f : 0.0;
    constexpr int kWidth = 40;
    std::string bar(size_t(f * kWidth), '=');
    bar.resize(kWidth, ' ');
    std::fprintf(stderr, "\r[%s] %3d%%  %6.1fs  ETA %6.1fs", bar.c_str(), int(f * 100.0), elapsed, eta);
    std::fflush(stderr);
}

}  // namespace whitted
