// The `whitted bench` subcommands (docs/performance.md): each adds itself under the CLI's `bench`
// command, so main.cpp only lists them.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace whitted::app {

/// A subcommand added under a parent: `app` is what CLI11 parsed into, `run` does the work and
/// returns the exit code (throwing whitted::Error for bad input, like everything else).
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

/// `whitted bench aa`: error against run time for every anti-aliasing mode (bench_aa.cpp).
Command register_bench_aa(CLI::App& bench);
/// `whitted bench accel`: build time, memory and Mrays/s of every accelerator (bench_accel.cpp).
Command register_bench_accel(CLI::App& bench);
/// `whitted bench anim`: per-frame update of an animated scene against a rebuild and a render (bench_anim.cpp).
Command register_bench_anim(CLI::App& bench);
/// `whitted bench env`: display error and time of N lights extracted from an environment (bench_env.cpp).
Command register_bench_env(CLI::App& bench);
/// `whitted bench materials`: each glTF material extension's sample with and without it (bench_materials.cpp).
Command register_bench_materials(CLI::App& bench);
/// `whitted bench process`: whole runs, start to file written, with their split (bench_process.cpp).
Command register_bench_process(CLI::App& bench);
/// `whitted bench quadrics`: analytic cylinders, cones and discs against tessellated ones (bench_quadrics.cpp).
Command register_bench_quadrics(CLI::App& bench);
/// `whitted bench scale`: load/build/render time and memory per object against object count (bench_scale.cpp).
Command register_bench_scale(CLI::App& bench);
/// `whitted bench skip`: what specialised kernels and skipped rays save (bench_skip.cpp).
Command register_bench_skip(CLI::App& bench);
/// `whitted bench stability`: the numerical-stability sweep (bench_stability.cpp).
Command register_bench_stability(CLI::App& bench);

}  // namespace whitted::app
