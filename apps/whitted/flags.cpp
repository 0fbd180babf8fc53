// Every flag of `whitted render`, `info` and `merge` (docs/cli.md lists them all): render's in one
// function per option group. The only file besides main.cpp that includes CLI11.
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "core/image_files_display.h"
#include "core/image_files_exr.h"
#include "integrator/render.h"
#include "flags.h"

namespace whitted::cli {

namespace {

/// Shown as a flag's default: "0.05" for a gray, "r,g,b" otherwise.
std::string color_text(const Color& c) {
    return c.x == c.y && c.y == c.z ? fmt::format("{}", c.x) : fmt::format("{},{},{}", c.x, c.y, c.z);
}

/// The scene, the image and the machine: the flags every render may set (no group).
void add_general(CLI::App* render, RenderCommand& c) {
    RenderSettings& rs = c.render;
    render->add_option("scene", c.input, "Scene file (.gltf, .glb, or a .json scene file: docs/scene-format.md)")
        ->required();
    render->add_option("-o,--output", c.output,
                       "Output image; the extension picks the format: .exr (scene-linear, AOVs), "
                       ".png/.jpg/.tif (display-referred through OCIO)")
        ->capture_default_str();
    render->add_option("--width", rs.width,
                       "Image width in pixels (0 = from the height and the aspect of the scene file or camera, "
                       "else 640)")
        ->check(CLI::Range(0, 32768))->capture_default_str();
    render->add_option("--height", rs.height,
                       "Image height in pixels (0 = from the width and the aspect of the scene file or camera)")
        ->check(CLI::Range(0, 32768))->capture_default_str();
    render->add_option("--camera", rs.camera, "Camera index (see `whitted info`)")->capture_default_str();
    render->add_option("--scene", c.import.scene_index, "glTF scene index (-1 = the file's default scene)")
        ->capture_default_str();
    render->add_option("--threads", rs.threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    render->add_option("--max-memory", c.max_memory_gb, "Refuse scenes whose data would exceed this many GiB")
        ->check(CLI::PositiveNumber)->capture_default_str();
    render->add_flag("--allow-outside-uris", c.import.allow_outside_uris,
                     "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");
}

/// Output: what the image holds and how it is encoded, beyond the shared colour flags.
void add_render_output(CLI::App* render, RenderCommand& c) {
    RenderSettings& rs = c.render;
    CLI::App* g = add_output_options(render, c.out);
    g->add_option_function<float>("--exposure", [&rs](float stops) { rs.exposure = std::exp2(stops); },
                                  "Exposure in stops: radiance is scaled by 2^exposure")
        ->default_str("0");
    g->add_option_function<std::vector<std::string>>(
         "--aov", [&rs](const std::vector<std::string>& names) { rs.aovs = parse_aovs(names); },
         "Extra EXR channels: depth, normal, albedo, primid, instid, aa_samples, all")
        ->delimiter(',');
    g->add_option_function<std::string>(
        "--crop", [&rs](const std::string& t) { if (!t.empty()) rs.crop = parse_crop(t); },
        "Render only the region x0,y0,x1,y1 (pixels, x1/y1 exclusive)");
}

/// Sampling: anti-aliasing, texture filtering and the depth of the ray tree.
void add_sampling(CLI::App* render, RenderSettings& rs) {
    CLI::App* g = render->add_option_group("Sampling", "Anti-aliasing and the ray tree (docs/antialiasing.md)");
    g->add_option_function<std::string>("--aa", [&rs](const std::string& name) { rs.aa.mode = parse_aa_mode(name); },
                                        "Anti-aliasing: center, corners, adaptive, stratified (docs/antialiasing.md)")
        ->check(CLI::IsMember({"center", "corners", "adaptive", "stratified"}))->default_str(aa_mode_name(rs.aa.mode));
    g->add_option("--aa-threshold", rs.aa.threshold,
                  "adaptive: split a square when its corners differ by more than this in display-referred "
                  "sRGB values (max channel difference); negative = always split")
        ->capture_default_str();
    g->add_option("--aa-depth", rs.aa.depth, "adaptive: maximum subdivision depth (sub-squares of 1/2^depth pixel)")
        ->check(CLI::Range(0, 8))->capture_default_str();
    g->add_option("--spp", rs.aa.spp, "stratified: samples per pixel, a square number k*k")
        ->check(CLI::Range(1, 4096))->capture_default_str();
    g->add_option_function<std::string>(
         "--filter", [&rs](const std::string& name) { rs.aa.filter = parse_pixel_filter(name); },
         "stratified: pixel filter, box or tent (radius 1 pixel)")
        ->check(CLI::IsMember({"box", "tent"}))->default_str(pixel_filter_name(rs.aa.filter));
    g->add_option_function<std::string>(
         "--texture-filter", [&rs](const std::string& name) { rs.aa.texture_filter = parse_texture_filter(name); },
         "Textures: mip (filtered over each sample's spacing: the pixel, pixel/k for stratified k*k, the "
         "sub-square for adaptive) or none (point samples of the finest level: Whitted's model exactly)")
        ->check(CLI::IsMember({"mip", "none"}))->default_str(texture_filter_name(rs.aa.texture_filter));
    g->add_option("--max-depth", rs.integrator.max_depth, "Maximum depth of the ray tree (0 = no reflection/refraction)")
        ->check(CLI::Range(0, 64))->capture_default_str();
    g->add_option("--min-weight", rs.integrator.min_weight,
                  "Adaptive tree depth (Hall & Greenberg 1983): skip reflected/refracted rays whose accumulated "
                  "weight is below this (default 1/255; 0 = trace to --max-depth)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
}

/// Lighting: ambient and background, the material mapping's switches, the environment.
void add_lighting(CLI::App* render, RenderCommand& c) {
    RenderSettings& rs = c.render;
    CLI::App* g = render->add_option_group("Lighting", "Light, background and materials (docs/lights.md, materials.md)");
    g->add_option_function<std::string>(
         "--background", [&rs](const std::string& t) { rs.integrator.background = parse_color(t, "--background"); },
         "Radiance of rays that hit nothing: r,g,b or gray (linear)")
        ->default_str(color_text(rs.integrator.background));
    g->add_option_function<std::string>(
         "--ambient", [&rs](const std::string& t) { rs.integrator.ambient = parse_color(t, "--ambient"); },
         "Ambient light Ia: r,g,b or gray (linear)")
        ->default_str(color_text(rs.integrator.ambient));
    g->add_flag("--fresnel", rs.integrator.fresnel, "Weight reflection and transmission with Schlick's Fresnel term");
    g->add_flag("--refract-thin", rs.mapping.refract_thin,
                "Refract through transmissive materials without KHR_materials_volume (classic glass)");
    g->add_option("--mirror-cutoff", rs.mapping.mirror_roughness_cutoff,
                  "Roughness at which mirror reflection has faded to 0 (see docs/materials.md)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    add_environment_options(g, c.import);
    g->add_option_function<std::string>(
         "--env-occlusion",
         [&rs](const std::string& t) { rs.integrator.env_occlusion = parse_env_occlusion(t, "--env-occlusion"); },
         "With an environment: directions per point over which the scene occludes its ambient light (a quarter "
         "as many glossy rays see the scene in rough reflections); off = the ambient unshadowed, the glossy "
         "term the prefiltered map alone (docs/environment.md)")
        ->default_str(std::to_string(rs.integrator.env_occlusion));
}

/// Acceleration: the ray-query backend and its options.
void add_acceleration(CLI::App* render, RenderCommand& c) {
    CLI::App* g = render->add_option_group("Acceleration", "The ray-query backend (docs/accelerators.md)");
    g->add_option("--accel", c.render.accel,
                  "Acceleration structure: embree, bvh, grid, octree, kdop, brute; options after a colon, "
                  "e.g. bvh:precision=double,bv=sphere (docs/accelerators.md)")->capture_default_str();
    g->add_option("--precision", c.precision,
                  "In-house BVH and brute force: trace in float or double (the reference), same as "
                  "--accel bvh:precision=...")->check(CLI::IsMember({"float", "double"}));
    g->add_option("--bv", c.bv,
                  "In-house BVH bounding volume: aabb or sphere (Whitted's (1980) bounding spheres), same as "
                  "--accel bvh:bv=...")->check(CLI::IsMember({"aabb", "sphere"}));
    g->add_flag("--robust,!--no-robust", c.render.robust,
                "Embree robust mode (RTC_SCENE_FLAG_ROBUST, the default): no light leaks at shared edges; "
                "--no-robust is 3-8% faster and leaks a few % of rays aimed at edges and vertices");
}

/// Distributed: a frame in pieces (tiles, tile jobs, checkpoints; docs/distributed.md).
void add_distributed(CLI::App* render, RenderCommand& c) {
    CLI::App* g = render->add_option_group("Distributed", "A frame in pieces: tiles, jobs, checkpoints, resume "
                                                          "(docs/distributed.md)");
    g->add_option("--tile-size", c.render.tile_size, "Tile size in pixels")->check(CLI::Range(1, 4096))
        ->capture_default_str();
    g->add_option("--tile-job", c.tile_job,
                  "Render only part i of n (i/n, 1 <= i <= n: horizontal bands) as an EXR part for `whitted "
                  "merge` (docs/distributed.md)");
    g->add_option("--checkpoint", c.checkpoint_seconds,
                  "Save the finished tiles to the checkpoint at least every this many seconds (an interrupted "
                  "render always saves them)")->check(CLI::PositiveNumber);
    g->add_flag("--resume", c.resume,
                "Continue from the checkpoint: render only the tiles it lacks (refused when it was made with "
                "other settings)");
    g->add_option("--checkpoint-file", c.checkpoint_file, "Checkpoint path (default: the output path + .checkpoint.exr)");
}

/// Animation: the moment of an animated glTF file (docs/gltf-support.md "Animation"), for `render` and `info`.
CLI::App* add_animation_options(CLI::App* app, ImportOptions& io) {
    CLI::App* g = app->add_option_group("Animation", "The moment an animated glTF file is posed at, or a sequence");
    g->add_option_function<double>(
         "--time", [&io](const double& t) { check_animation_time(t, "--time"); io.time = t; },
         "Seconds into the animations (before the first key: the first value; after the last: the last)")
        ->default_str("0");
    g->add_option("--animation", io.animation, "Animations applied: all, a name, or indices (0,2)")
        ->capture_default_str();
    g->add_flag("--loop", io.loop, "Each animation repeats after its duration instead of holding its last key");
    app->add_option("--variant", io.variant,
                    "KHR_materials_variants: the variant whose materials apply (by name; `whitted info` lists them; "
                    "default: the file's default materials)");
    return g;
}

/// render's sequence flags, in the Animation group.
void add_sequence_options(CLI::App* group, RenderCommand& c) {
    group->add_option("--frames", c.frames,
                      "Render frames A-B as an image sequence: frame k at --time k/fps, written to the output name "
                      "with its '#' run replaced by k (out_####.exr -> out_0000.exr ...)");
    group->add_option("--fps", c.fps, "Frames per second of --frames")->check(CLI::PositiveNumber)->capture_default_str();
    group->add_option("--orbit", c.orbit,
                      "With --frames: the default camera turns this many degrees about the up axis over the sequence "
                      "(a turntable)")
        ->capture_default_str();
}

/// Diagnostics: measurement knobs and what the run shows of itself.
void add_diagnostics(CLI::App* render, RenderCommand& c) {
    CLI::App* g = render->add_option_group("Diagnostics", "Measurement knobs and progress");
    g->add_flag_function("--no-progress", [&c](std::int64_t) { c.render.progress = false; },
                         "Do not draw the progress bar");
    g->add_flag_function("--no-specialize", [&c](std::int64_t) { c.render.integrator.specialize = false; },
                         "Use the general shading kernel instead of the one the scene needs (to measure the gain)");
    g->add_option_function<std::string>(
         "--tile-order",
         [&c](const std::string& v) {
             c.tile_order = v == "frame" ? TileOrder::Frame : v == "cost" ? TileOrder::ExpensiveFirst : TileOrder::Auto;
         },
         "Order the tiles are rendered in: cost (the dearest first, by a probe of 16 ray trees per tile, so "
         "that the last tiles are cheap), frame (row by row), or auto (cost from 8 worker threads over all "
         "processes on, else frame)")
        ->check(CLI::IsMember({"auto", "cost", "frame"}))->default_str("auto");
    g->add_option("--tile-log", c.tile_log,
                  "Write each tile's render time (and its message size to MPI rank 0) as CSV, for "
                  "scripts/simulate_mpi.py");
}

}  // namespace

void add_environment_options(CLI::App* g, ImportOptions& io) {
    g->add_option("--environment", io.environment,
                  "Lat-long HDR map around the scene (a file, or a bundled name: studio, city, courtyard, "
                  "forest, interior, sunset); replaces the scene file's");
    g->add_option_function<float>("--env-rotate", [&io](const float& deg) { io.environment_rotation = deg; },
                                  "Turn the environment about +Y by this many degrees");
    g->add_option_function<float>("--env-exposure", [&io](const float& stops) { io.environment_exposure = stops; },
                                  "Scale the environment's radiance by 2^stops");
    g->add_option("--env-lights", io.environment_lights,
                  "Directional lights extracted from the environment's brightest regions (0 = all of its light "
                  "is ambient)")->check(CLI::Range(0, 4096))->capture_default_str();
    g->add_flag("--no-environment", io.no_environment, "No environment, whatever the scene file names");
}

CLI::App* add_output_options(CLI::App* app, OutputSettings& out) {
    CLI::App* g = app->add_option_group("Output", "Colour pipeline and file encoding (docs/color.md)");
    g->add_option("--ocio-config", out.color.config, "OpenColorIO config (default: $OCIO, else the bundled one)");
    g->add_option("--display", out.color.display, "OCIO display (default: the config's default)");
    g->add_option("--view", out.color.view, "OCIO view: Standard, ACES 1.0 SDR-video, Raw")->capture_default_str();
    g->add_option("--bits", out.bits, "Bits per channel for PNG/TIFF: 8 or 16 (0 = format default)")
        ->check(CLI::IsMember({0, 8, 16}))->capture_default_str();
    g->add_flag_function("--exr-float", [&out](std::int64_t) { out.exr_half = false; },
                         "Write EXR beauty as 32-bit float instead of half");
    g->add_option("--exr-compression", out.exr_compression,
                  "EXR compression, lossless: none, rle, zips, zip, piz; zip/zips take a zlib level, e.g. zip:6 "
                  "(zip = zip:1; none writes fastest, at about 3x the bytes of zip for a float beauty)")
        ->check([](const std::string& v) { return exr_compression_error(v); })
        ->capture_default_str();
    g->add_option("--tiff-compression", out.tiff_compression,
                  "TIFF compression, lossless: zip (Deflate with the horizontal predictor; zip:N, N = 1-12) or "
                  "none (a 16-bit TIFF about 1.3x faster, at about 7x the bytes)")
        ->check([](const std::string& v) { return tiff_compression_error(v); })
        ->capture_default_str();
    return g;
}

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
    add_animation_options(info, c.import);
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

CLI::App* add_render_command(CLI::App& app, RenderCommand& c) {
    CLI::App* render = app.add_subcommand("render", "Render a scene to an image");
    add_general(render, c);
    add_render_output(render, c);
    add_sampling(render, c.render);
    add_lighting(render, c);
    add_sequence_options(add_animation_options(render, c.import), c);
    add_acceleration(render, c);
    add_distributed(render, c);
    add_diagnostics(render, c);
    return render;
}

}  // namespace whitted::cli
