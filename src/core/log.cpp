#include "core/log.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>

#include "core/error.h"

namespace whitted {

namespace {
std::atomic<int> g_level{int(LogLevel::Info)};
std::mutex g_mutex;
}  // namespace

void set_log_level(LogLevel level) { g_level = int(level); }
LogLevel log_level() { return LogLevel(g_level.load()); }

LogLevel parse_log_level(std::string_view name) {
    if (name == "debug") return LogLevel::Debug;
    if (name == "info") return LogLevel::Info;
    if (name == "warning" || name == "warn") return LogLevel::Warning;
    if (name == "error") return LogLevel::Error;
    if (name == "off") return LogLevel::Off;
    throw Error(fmt::format("unknown log level '{}' (expected debug, info, warning, error or off)", name));
}

void log_line(LogLevel level, std::string_view message) {
    if (int(level) < g_level.load()) return;
    static const char* names[] = {"debug", "info", "warning", "error"};
    std::string line = fmt::format("[{}] {}\n", names[std::min(int(level), 3)], message);
    std::lock_guard lock(g_mutex);
    std::fwrite(line.data(), 1, line.size(), stderr);
    std::fflush(stderr);
}

}  // namespace whitted
