#include "info_merge.h"

#include <cstdio>
#include <map>

#include "importers/scene_report.h"
#include "session/tile_job.h"

namespace whitted::cli {

int run_info(const InfoCommand& c) {
    const Scene scene = load_scene(c.input, c.import);
    std::fputs(describe_scene(scene, c.verbose ? ReportDetail::Verbose : ReportDetail::Summary).c_str(), stdout);
    return 0;
}

int run_merge(MergeCommand c, const std::string& cmdline) {
    OutputSettings& os = c.out;
    { DisplayTransform check(os.color); }
    std::map<std::string, std::string> meta;
    bool half_parts = false;
    const Film film = merge_parts(c.parts, &meta, &half_parts);
    // The parts' precision unless a flag asks otherwise: --exr-float set exr_half = false already.
    const bool float_asked = !os.exr_half;
    os.exr_half = c.exr_half || (half_parts && !float_asked);
    for (const auto& [key, value] : meta) os.metadata[key] = value;
    os.metadata["whitted:commandLine"] = cmdline;
    os.metadata["whitted:version"] = WHITTED_VERSION;
    write_image(film, c.output, os);
    std::fprintf(stderr, "whitted: wrote %s (%dx%d) from %zu parts\n", c.output.c_str(), film.width(), film.height(),
                 c.parts.size());
    return 0;
}

}  // namespace whitted::cli
