// whitted-bench: the `whitted bench` commands (benchmarks/bench_commands.h), a program of their own
// so that the renderer builds without them; `whitted bench ...` runs this with its arguments. Its
// command line is `whitted bench NAME ...`, as the user typed it (docs/performance.md).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "benchmarks/bench_commands.h"
#include "core/error.h"
#include "core/huge_pages.h"
#include "core/log.h"

int main(int argc, char** argv) {
    using namespace whitted;
    restart_with_huge_pages(argv);
    CLI::App app{"whitted: a Whitted-style (1980) recursive ray tracer for glTF 2.0 scenes", "whitted"};
    app.require_subcommand(1);
    std::string log_level = "info";
    app.add_option("--log-level", log_level, "Messages to print: debug, info, warning, error, off")
        ->check(CLI::IsMember({"debug", "info", "warning", "error", "off"}))
        ->capture_default_str();
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print figures, write CSV and plots");
    bench->require_subcommand(1);
    bench->fallthrough();
    // Each benchmark module registers itself here (one line each; benchmarks/bench_commands.h):
    std::vector<app::Command> commands{app::register_bench_aa(*bench),        app::register_bench_accel(*bench),
                                       app::register_bench_anim(*bench),      app::register_bench_env(*bench),
                                       app::register_bench_materials(*bench), app::register_bench_process(*bench),
                                       app::register_bench_quadrics(*bench),  app::register_bench_scale(*bench),
                                       app::register_bench_skip(*bench),
                                       app::register_bench_stability(*bench)};
    for (app::Command& c : commands) c.app->fallthrough();
    try {
        app.parse(argc, argv);
    } catch (const Error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        std::fprintf(stderr, "whitted: error: %s (see whitted bench --help)\n", e.what());
        return 2;
    }
    try {
        set_log_level(parse_log_level(log_level));
        for (app::Command& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const Error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
