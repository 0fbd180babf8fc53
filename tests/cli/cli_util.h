// Running the `whitted` executable from a test (WHITTED_EXE, set by tests/CMakeLists.txt).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace whitted::test {

/// Exit code (128 + signal when killed) and the captured output of one run.
struct Result {
    int code = -1;
    std::string out, err;
};

/// Whole file as a string ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Runs the whitted executable with `args` (shell-quoted by the caller), stdin from /dev/null;
/// stdout and stderr go through files in a per-process scratch folder.
inline Result run(const std::string& args) {
    static int counter = 0;
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("whitted_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::filesystem::path out = dir / ("out" + std::to_string(counter) + ".txt");
    const std::filesystem::path err = dir / ("err" + std::to_string(counter++) + ".txt");
    const std::string cmd = std::string("'") + WHITTED_EXE + "' " + args + " >'" + out.string() + "' 2>'" +
                            err.string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

}  // namespace whitted::test
