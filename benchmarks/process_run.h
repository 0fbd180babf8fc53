// Whole runs of another program, timed from spawn to exit (`whitted bench process`).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace whitted::app {

/// One complete run: wall time, peak RSS, exit status and what it printed on stderr.
struct Run {
    double seconds = 0.0;
    double cpu_seconds = 0.0;  ///< user + system time of the process (wait4's rusage)
    size_t peak_bytes = 0;
    int code = 0;
    std::string err;
};

/// Runs `exe` (argv[0] `name`) with `args` in the folder `cwd` (empty: this process's), stdout
/// to /dev/null, stderr to `err_file`; the wall time from spawn to exit and the peak resident
/// memory (wait4's rusage). Throws whitted::Error when it cannot be started.
Run run_program(const std::string& exe, const std::string& name, const std::vector<std::string>& args,
                const std::filesystem::path& err_file, const std::filesystem::path& cwd = {});

/// The program `name` on the PATH (or `name` itself when it names a file); empty when not found.
std::string find_program(const std::string& name);

/// Median of `v` (0 for none).
double median(std::vector<double> v);

/// The first line of `text`.
std::string first_line(const std::string& text);

}  // namespace whitted::app
