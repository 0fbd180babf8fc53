// Whole-line, thread-safe logging to stderr with levels set by --log-level.
#pragma once

#include <string>
#include <string_view>

#include <fmt/format.h>

namespace whitted {

enum class LogLevel { Debug = 0, Info = 1, Warning = 2, Error = 3, Off = 4 };

/// Sets the minimum level printed (default Info).
void set_log_level(LogLevel level);
LogLevel log_level();
/// Parses "debug|info|warning|error|off"; throws whitted::Error on anything else.
LogLevel parse_log_level(std::string_view name);
/// Prints one whole line "[level] message" to stderr; lines from threads never interleave.
void log_line(LogLevel level, std::string_view message);

template <typename... Args>
void log_debug(fmt::format_string<Args...> f, Args&&... args) {
    if (log_level() <= LogLevel::Debug) log_line(LogLevel::Debug, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void log_info(fmt::format_string<Args...> f, Args&&... args) {
    if (log_level() <= LogLevel::Info) log_line(LogLevel::Info, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void log_warning(fmt::format_string<Args...> f, Args&&... args) {
    if (log_level() <= LogLevel::Warning) log_line(LogLevel::Warning, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace whitted
