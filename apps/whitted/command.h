// Subcommands beyond render/info (e.g. `whitted bench accel`) live in their own files and register
// themselves here, so main.cpp only lists them.
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

}  // namespace whitted::app
