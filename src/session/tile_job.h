// Tile jobs without MPI: `--tile-job i/n` renders the i-th of n horizontal bands of the frame as
// an EXR part (the full display window, the band as its data window, metadata naming the job and
// its settings), and merge_parts() checks that the parts belong together and cover the frame
// exactly once, and assembles it (docs/distributed.md).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "film/film.h"
#include "integrator/render_settings.h"
#include "output/image_output.h"

namespace whitted {

/// Job `index` (1-based) of `count`.
struct TileJob {
    int index = 1, count = 1;
};

/// Parses "i/n" with 1 <= i <= n; throws whitted::Error naming --tile-job otherwise.
TileJob parse_tile_job(const std::string& text);

/// The job's band of `frame`: rows split as evenly as possible (the first frame.height() % n
/// bands one row taller), in order from the top. Throws whitted::Error when there are fewer rows
/// than jobs.
PixelWindow tile_job_window(const PixelWindow& frame, const TileJob& job);

/// Metadata a part carries: the job, the frame it belongs to and the settings it was made with.
std::map<std::string, std::string> tile_job_metadata(const TileJob& job, const PixelWindow& frame,
                                                     const SettingList& identity);

/// Reads the parts and assembles their frame. Throws whitted::Error naming the file and the
/// problem: not a part, parts of other frames or settings (the first setting that differs),
/// overlapping parts, a missing part (its number and rows). `half_parts`, when given, is set to
/// whether every part stores its beauty as half floats (tile jobs write float: the merge then keeps
/// float, so nothing is lost).
Film merge_parts(const std::vector<std::string>& paths, std::map<std::string, std::string>* metadata = nullptr,
                 bool* half_parts = nullptr);

}  // namespace whitted
