// The flags of `whitted render`, `info` and `merge`, in CLI11 option groups by task, parsed
// straight into the commands' settings (render_command.h, info_merge.h).
#pragma once

#include <CLI/CLI.hpp>

#include "info_merge.h"
#include "render_command.h"

namespace whitted::cli {

/// Adds `render` to `app` with every flag writing into `c`.
CLI::App* add_render_command(CLI::App& app, RenderCommand& c);
/// Adds `info` to `app`.
CLI::App* add_info_command(CLI::App& app, InfoCommand& c);
/// Adds `merge` to `app`.
CLI::App* add_merge_command(CLI::App& app, MergeCommand& c);

/// The environment flags (docs/environment.md), shared by `render` and `info`, added to `group`
/// (an option group of either).
void add_environment_options(CLI::App* group, ImportOptions& io);
/// The output flags (colour pipeline, bits, EXR and TIFF encoding), shared by `render` and `merge`,
/// in the "Output" group.
CLI::App* add_output_options(CLI::App* app, OutputSettings& out);

}  // namespace whitted::cli
