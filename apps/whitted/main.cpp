// whitted: the command-line front end. Each command parses its flags into the library's settings
// (flags.h) and calls the library: `render` (render_command.h), `info` and `merge` (info_merge.h).
// `whitted bench ...` runs the whitted-bench program beside this one (apps/whitted-bench: the
// commands of benchmarks/), so that the renderer builds without them.
//
// Errors from bad input or bad flags end in exactly one line on stderr and a non-zero exit code:
// 2 for command-line errors, 1 for everything else.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/error.h"
#include "core/huge_pages.h"
#include "core/log.h"
#include "flags.h"
#include "interrupt.h"
#include "session/mpi_frame.h"

namespace {

using namespace whitted;
using namespace whitted::cli;

std::string command_line(int argc, char** argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) {
        if (i) s += ' ';
        s += argv[i];
    }
    return s;
}

/// Every command of the program and what its flags parse into.
struct Commands {
    std::string log_level = "info";
    RenderCommand render;
    InfoCommand info;
    MergeCommand merge;
    CLI::App* render_app = nullptr;
    CLI::App* info_app = nullptr;
    CLI::App* merge_app = nullptr;
};

/// Builds the command line: global options, render, info, merge and bench <name>.
void add_commands(CLI::App& app, Commands& c) {
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("whitted ") + WHITTED_VERSION);
    app.add_option("--log-level", c.log_level, "Messages to print: debug, info, warning, error, off")
        ->check(CLI::IsMember({"debug", "info", "warning", "error", "off"}))
        ->capture_default_str();
    c.render_app = add_render_command(app, c.render);
    c.info_app = add_info_command(app, c.info);
    c.merge_app = add_merge_command(app, c.merge);

    // Listed for --help only: run_bench_program() hands `bench` to whitted-bench before parsing.
    app.add_subcommand("bench", "Benchmarks: print figures, write CSV and plots (the whitted-bench program; "
                                "docs/performance.md)");

    // Global options (--log-level) may also follow the subcommand.
    for (CLI::App* sub : {c.render_app, c.info_app, c.merge_app}) sub->fallthrough();
}

/// `whitted [--log-level L] bench ...`: replaces this process by whitted-bench, beside this program,
/// with the same arguments; nothing when the command is another. Returns the exit code when
/// whitted-bench cannot run (not built, say).
std::optional<int> run_bench_program(int argc, char** argv) {
    int i = 1;
    while (i < argc && std::strncmp(argv[i], "--log-level", 11) == 0) i += std::strchr(argv[i], '=') ? 1 : 2;
    if (i >= argc || std::strcmp(argv[i], "bench") != 0) return std::nullopt;
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path() / "whitted-bench";
    if (ec || !std::filesystem::exists(exe)) {
        std::fprintf(stderr, "whitted: error: bench: %s is not built (the bench commands are their own program: "
                     "cmake --build build/release --target whitted-bench, or bash scripts/dev test)\n", exe.c_str());
        return 1;
    }
    std::vector<char*> args(argv, argv + argc + 1);
    args[0] = const_cast<char*>(exe.c_str());
    ::execv(exe.c_str(), args.data());
    std::fprintf(stderr, "whitted: error: bench: cannot run %s: %s\n", exe.c_str(), std::strerror(errno));
    return 1;
}

/// Parses the command line; returns the exit code when the run ends here (help, version, a bad flag).
std::optional<int> parse(CLI::App& app, int argc, char** argv) {
    // Flags parsed into their types (colours, crop, AOVs) throw whitted::Error while CLI11 parses:
    // reported like every other Error, in one line with exit code 1.
    try {
        app.parse(argc, argv);
    } catch (const Error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::Success& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "whitted: error: %s (see whitted --help)\n", e.what());
        return 2;
    }
    return std::nullopt;
}

/// Runs the parsed command.
int run(Commands& c, const std::string& cmdline) {
    MpiSession* mpi = interrupts().mpi;
    const LogLevel level = parse_log_level(c.log_level);
    set_log_level(level);
    log_debug("malloc: transparent huge pages {}", huge_pages_requested() ? "requested (GLIBC_TUNABLES)" : "not requested");
    // Under MPI only rank 0 reports; the others print errors only (each rank loads the same scene).
    if (mpi && mpi->rank() > 0) set_log_level(std::max(level, LogLevel::Error));
    if (c.render_app->parsed()) {
        // A setting's scene-file key names its flag: aa_threshold -> --aa-threshold.
        const SettingGiven flag_given = [&](std::string_view key) { return c.render_app->count(setting_flag(key)) > 0; };
        return run_render(c.render, cmdline, flag_given, mpi);
    }
    if (c.info_app->parsed()) return run_info(c.info);
    if (c.merge_app->parsed()) return run_merge(c.merge, cmdline);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // Big buffers (images, environment maps, accelerators) fault in 2 MiB pages: on the machines
    // measured, page faults were half the time of a small run (docs/performance.md).
    restart_with_huge_pages(argv);
    if (const std::optional<int> failed = run_bench_program(argc, argv)) return *failed;
    // Under an MPI launcher (mpirun -n N whitted render ...): MPI for the process's life; a plain
    // run never initialises it (docs/distributed.md).
    std::optional<MpiSession> mpi;
    if (launched_by_mpi() && mpi_available()) {
        mpi.emplace();
        interrupts().mpi = &*mpi;
    }
    CLI::App app{"whitted: a Whitted-style (1980) recursive ray tracer for glTF 2.0 scenes"};
    Commands commands;
    add_commands(app, commands);
    if (const std::optional<int> code = parse(app, argc, argv)) return *code;
    try {
        return run(commands, command_line(argc, argv));
    } catch (const MpiSetupFailed& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const Error& e) {
        if (mpi && interrupts().mpi_running.load()) {
            std::fprintf(stderr, "whitted: error: rank %d: %s\n", mpi->rank(), e.what());
            mpi->abort(1);
        }
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "whitted: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    }
}
