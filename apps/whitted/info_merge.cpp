#include "info_merge.h"

#include <cstdio>
#include <map>

#include "importers/scene_report.h"
#include "render_command.h"
#include "session/tile_job.h"

namespace whitted::cli {

CLI::App* add_info_command(CLI::App& app, InfoCommand& c) {
    CLI::App* info = app.add_subcommand("info", "Print what a scene file contains after import");
    info->add_option("scene", c.input, "Scene file (.gltf, .glb or .json)")->required();
    info->add_option("--scene", c.import.scene_index, "glTF scene index (-1 = the file's default scene)")
        ->capture_default_str();
    info->add_flag_function("--no-textures", [&c](std::int64_t) { c.import.load_textures = false; },
                            "Skip decoding images");
    info->add_flag("--allow-outside-uris", c.import.allow_outside_uris,
                   "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");
    info->add_flag("-v,--verbose", c.verbose,
                   "List every light extracted from the environment (by default: their count, share and the "
                   "brightest few)");
    add_environment_options(info->add_option_group("Lighting", "The environment (docs/environment.md)"), c.import);
    return info;
}

CLI::App* add_merge_command(CLI::App& app, MergeCommand& c) {
    CLI::App* merge = app.add_subcommand("merge", "Assemble the EXR parts of `render --tile-job i/n` into the frame");
    merge->add_option("parts", c.parts, "The parts (EXR files written with --tile-job), in any order")->required();
    merge->add_option("-o,--output", c.output, "Output image; the extension picks the format, as for `render`")
        ->required();
    CLI::App* output = add_output_options(merge, c.out);
    CLI::Option* half = output->add_flag("--exr-half", c.exr_half,
                                         "Write the EXR beauty as half floats (default: as the parts store it, "
                                         "float for tile-job parts)");
    half->excludes(output->get_option("--exr-float"));
    return merge;
}

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
