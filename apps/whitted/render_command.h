// `whitted render`: what its flags parse into (flags.h), and the run: load, configure, render the
// frame (tiles, checkpoints, MPI ranks), write, summarise.
#pragma once

#include <string>

#include "importers/scene_loader.h"
#include "integrator/render_settings.h"
#include "output/image_output.h"
#include "session/frame_render.h"

namespace whitted {
class MpiSession;
}

namespace whitted::cli {

/// What `whitted render` collects: the library's settings, which the flags set directly, and the
/// few flags that are only other spellings of them.
struct RenderCommand {
    std::string input;                          ///< scene file
    std::string output = "whitted.png";         ///< image file; the extension picks the format
    ImportOptions import;                       ///< glTF scene index, outside URIs, environment
    RenderSettings render = command_line_render_settings();
    OutputSettings out;                         ///< OCIO config, display and view, bits, EXR half
    std::string precision, bv;                  ///< in-house BVH options appended to the --accel spec
    double max_memory_gb = 8.0;                 ///< ImportOptions::max_memory and the accelerators', in GiB
    std::string tile_job;                       ///< "i/n": render the i-th of n bands as an EXR part
    double checkpoint_seconds = 0.0;            ///< > 0: save finished tiles this often
    bool resume = false;                        ///< continue from the checkpoint
    std::string checkpoint_file;                ///< empty: beside the output (checkpoint_path_for)
    std::string tile_log;                       ///< CSV of per-tile times (docs/measurements/distributed.md)
    TileOrder tile_order = TileOrder::Auto;
    std::string frames;                         ///< "A-B": an image sequence (session/sequence.h); empty: one image
    double fps = 24.0;                          ///< frames per second of the sequence: frame k at time k / fps
    double orbit = 0.0;                         ///< degrees the default camera turns about +Y over the sequence
};

/// Runs `whitted render`: `given` tells which settings a flag set (they win over the scene file's);
/// `mpi` is the process's MPI session (null in a plain run). Returns the exit code.
int run_render(RenderCommand c, const std::string& cmdline, const SettingGiven& given, MpiSession* mpi);

}  // namespace whitted::cli
