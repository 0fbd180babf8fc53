// The one error type of whitted: bad input throws whitted::Error carrying where it came from
// (file plus JSON pointer or line), main() catches it once and prints one line.
#pragma once

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace whitted {

/// Where a problem was found: a file and, when known, a JSON pointer ("/accessors/3") or line.
struct FileLoc {
    std::string file;     ///< path as the user gave it; empty when not from a file
    std::string pointer;  ///< JSON pointer inside the file, e.g. "/accessors/3"; may be empty
    int line = 0;         ///< 1-based line, 0 = unknown
    int column = 0;       ///< 1-based column, 0 = unknown

    std::string to_string() const {
        std::string s = file;
        if (line > 0) s += fmt::format(":{}", line);
        if (line > 0 && column > 0) s += fmt::format(":{}", column);
        if (!pointer.empty()) s += (s.empty() ? "" : ": ") + pointer;
        return s;
    }
};

/// Error raised for bad input or a failing library call. what() is the full one-line message.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
    Error(const FileLoc& loc, const std::string& message)
        : std::runtime_error(loc.to_string().empty() ? message : loc.to_string() + ": " + message), m_loc(loc) {}
    const FileLoc& location() const { return m_loc; }

private:
    FileLoc m_loc;
};

}  // namespace whitted

/// Invariant check that prints both sides; throws whitted::Error (never aborts the process).
#define RT_CHECK(cond)                                                                                     \
    do {                                                                                                   \
        if (!(cond)) throw ::whitted::Error(fmt::format("internal check failed at {}:{}: {}", __FILE__, __LINE__, #cond)); \
    } while (0)
#define RT_CHECK_EQ(a, b)                                                                                  \
    do {                                                                                                   \
        if (!((a) == (b)))                                                                                 \
            throw ::whitted::Error(fmt::format("internal check failed at {}:{}: {} == {} ({} vs {})", __FILE__, \
                                               __LINE__, #a, #b, (a), (b)));                               \
    } while (0)
#ifndef NDEBUG
#define RT_DCHECK(cond) RT_CHECK(cond)
#else
#define RT_DCHECK(cond) ((void)0)
#endif
