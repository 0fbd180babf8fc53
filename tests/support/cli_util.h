// Running the `whitted` executable from a test (WHITTED_EXE, set by tests/CMakeLists.txt).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

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

/// The per-process folders process_folder() made: removed when the test program ends with every
/// test passed, kept after a failure (to look into). UnitTest's instance is never destroyed, so it
/// is still there when this static is.
struct ProcessFolders {
    std::vector<std::filesystem::path> paths;
    ~ProcessFolders() {
        if (!::testing::UnitTest::GetInstance()->Passed()) return;
        std::error_code ec;
        for (const std::filesystem::path& p : paths) std::filesystem::remove_all(p, ec);
    }
};

/// <tmp>/<prefix>_<pid>, created if needed (per process, so parallel ctest runs do not share it)
/// and removed at the end of a passing run (ProcessFolders).
inline std::filesystem::path process_folder(const std::string& prefix) {
    static ProcessFolders folders;
    std::string name = prefix;  // appended, not `prefix + "_" + ...` (a -Wrestrict false positive)
    name += '_';
    name += std::to_string(::getpid());
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
    if (std::find(folders.paths.begin(), folders.paths.end(), dir) == folders.paths.end()) folders.paths.push_back(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

/// Runs `exe` with `args` (shell-quoted by the caller), stdin from /dev/null; stdout and stderr go
/// through files in a per-process scratch folder.
inline Result run_program(const std::string& exe, const std::string& args) {
    static int counter = 0;
    const std::filesystem::path dir = process_folder("whitted_cli");
    const std::filesystem::path out = dir / ("out" + std::to_string(counter) + ".txt");
    const std::filesystem::path err = dir / ("err" + std::to_string(counter++) + ".txt");
    const std::string cmd = std::string("'") + exe + "' " + args + " >'" + out.string() + "' 2>'" +
                            err.string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

#ifdef WHITTED_EXE
/// Runs the whitted executable with `args` (run_program).
inline Result run(const std::string& args) { return run_program(WHITTED_EXE, args); }
#endif

/// A folder for one test's files, created if needed: <tmp>/<prefix>_<pid>/<name> (process_folder).
inline std::filesystem::path scratch_dir(const std::string& prefix, const std::string& name) {
    const std::filesystem::path dir = process_folder(prefix) / name;
    std::filesystem::create_directories(dir);
    return dir;
}

/// `p` in single quotes, for the shell command lines the tests build.
inline std::string quoted(const std::filesystem::path& p) {
    std::string s = "'";  // appended: `"'" + ...` trips a -Wrestrict false positive in GCC 12
    s += p.string();
    s += '\'';
    return s;
}

/// Waits up to `seconds` for child `pid`; its exit code (128 + signal when killed), or -1 when
/// it was still running (then it is killed).
inline int wait_exit(pid_t pid, double seconds) {
    int status = 0;
    for (int i = 0; i < int(seconds * 20); ++i) {
        if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        ::usleep(50 * 1000);
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    return -1;
}

/// Whether `part` occurs in `s` (the tests' check on captured output).
inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// A CSV as rows of column -> value. Fields may be double-quoted (bench skip quotes its kernel
/// names, which hold commas; "" inside quotes is a quote). A row with the wrong number of fields
/// also gets "_bad" = the line.
inline std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& path,
                                                                std::vector<std::string>* header = nullptr) {
    std::istringstream in(slurp(path));
    std::string line;
    std::vector<std::string> columns;
    std::vector<std::map<std::string, std::string>> rows;
    auto split = [](const std::string& l) {
        std::vector<std::string> f(1);
        bool quoted = false;
        for (size_t i = 0; i < l.size(); ++i) {
            const char ch = l[i];
            if (quoted && ch == '"' && i + 1 < l.size() && l[i + 1] == '"') f.back() += l[++i];
            else if (ch == '"') quoted = !quoted;
            else if (ch == ',' && !quoted) f.emplace_back();
            else f.back() += ch;
        }
        return f;
    };
    if (!std::getline(in, line)) return rows;
    columns = split(line);
    if (header) *header = columns;
    while (std::getline(in, line)) {
        const std::vector<std::string> f = split(line);
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < columns.size() && i < f.size(); ++i) row[columns[i]] = f[i];
        if (f.size() != columns.size()) row["_bad"] = line;
        rows.push_back(row);
    }
    return rows;
}

/// The number in `column` of a read_csv row (throws when the column is missing).
inline double num(const std::map<std::string, std::string>& row, const std::string& column) {
    return std::stod(row.at(column));
}

}  // namespace whitted::test
