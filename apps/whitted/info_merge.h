// `whitted info` (what the importer made of a file) and `whitted merge` (tile-job parts into
// their frame): what their flags parse into (flags.h), and the runs.
#pragma once

#include <string>
#include <vector>

#include "importers/scene_loader.h"
#include "output/image_output.h"

namespace whitted::cli {

struct InfoCommand {
    std::string input;      ///< scene file
    ImportOptions import;   ///< glTF scene index, textures, environment
    bool verbose = false;   ///< every light extracted from the environment, not only the brightest
};

struct MergeCommand {
    std::vector<std::string> parts;  ///< EXR files written with --tile-job
    std::string output;              ///< the frame; the extension picks the format
    OutputSettings out;
    bool exr_half = false;           ///< --exr-half: a half-float beauty whatever the parts hold
};

/// Prints the scene's description (describe_scene) on stdout; returns the exit code.
int run_info(const InfoCommand& c);
/// Merges the parts and writes the frame like `render` writes one; returns the exit code.
int run_merge(MergeCommand c, const std::string& cmdline);

}  // namespace whitted::cli
