// whitted: the command-line front end (`whitted render`, `whitted info`).
//
// Errors from bad input or bad flags end in exactly one line on stderr and a non-zero exit code:
// 2 for command-line errors, 1 for everything else.
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/whitted/command.h"
#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "renderer/core/error.h"
#include "renderer/core/log.h"
#include "renderer/integrator/render.h"
#include "renderer/output/image_output.h"

namespace {

using namespace whitted;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// "r,g,b" or a single gray value.
Color parse_color(const std::string& text, const char* flag) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, ',')) {
        try {
            size_t used = 0;
            float f = std::stof(part, &used);
            if (used != part.size() || !std::isfinite(f)) throw std::invalid_argument(part);
            v.push_back(f);
        } catch (const std::exception&) {
            throw Error(fmt::format("{}: '{}' is not a color (expected r,g,b or a single value)", flag, text));
        }
    }
    if (v.size() == 1) return Color(v[0]);
    if (v.size() == 3) return {v[0], v[1], v[2]};
    throw Error(fmt::format("{}: '{}' is not a color (expected r,g,b or a single value)", flag, text));
}

AovSet parse_aovs(const std::vector<std::string>& names) {
    AovSet a;
    for (const std::string& n : names) {
        if (n == "depth" || n == "z") a.depth = true;
        else if (n == "normal" || n == "n") a.normal = true;
        else if (n == "albedo") a.albedo = true;
        else if (n == "primid" || n == "prim_id" || n == "primitive") a.prim_id = true;
        else if (n == "instid" || n == "inst_id" || n == "instance") a.inst_id = true;
        else if (n == "all") a = AovSet{true, true, true, true, true};
        else throw Error(fmt::format("--aov: unknown AOV '{}' (available: depth, normal, albedo, primid, instid, all)", n));
    }
    return a;
}

std::string command_line(int argc, char** argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
    return s;
}

struct RenderOptions {
    std::string input, output = "whitted.png";
    int width = 0, height = 0, camera = 0, scene = -1, max_depth = 5, tile_size = 32, threads = 0, bits = 0;
    std::string background = "0", ambient = "0.05", crop, accel = "embree", ocio_config, display, view = "Standard";
    std::vector<std::string> aovs;
    float exposure = 0.f, mirror_cutoff = 0.3f;
    bool fresnel = false, refract_thin = false, robust = false, no_progress = false, exr_float = false;
    double max_memory_gb = 8.0;
};

int run_render(const RenderOptions& o, const std::string& cmdline) {
    const auto t_load = Clock::now();
    ImportOptions io;
    io.scene_index = o.scene;
    io.max_memory = size_t(o.max_memory_gb * double(size_t(1) << 30));
    Scene scene = load_scene(o.input, io);
    const double load_s = seconds_since(t_load);
    for (const std::string& w : scene.warnings) log_warning("{}: {}", o.input, w);

    RenderSettings rs;
    rs.width = o.width;
    rs.height = o.height;
    rs.camera = o.camera;
    rs.integrator.max_depth = o.max_depth;
    rs.integrator.background = parse_color(o.background, "--background");
    rs.integrator.ambient = parse_color(o.ambient, "--ambient");
    rs.integrator.fresnel = o.fresnel;
    rs.mapping.refract_thin = o.refract_thin;
    rs.mapping.mirror_roughness_cutoff = o.mirror_cutoff;
    rs.exposure = std::exp2(o.exposure);
    rs.tile_size = o.tile_size;
    rs.threads = o.threads;
    if (!o.crop.empty()) rs.crop = parse_crop(o.crop);
    rs.aovs = parse_aovs(o.aovs);
    rs.accel = o.accel;
    rs.robust = o.robust;
    rs.progress = !o.no_progress;

    // Resolve the output and color pipeline before the (long) render so bad flags fail fast.
    OutputSettings os;
    os.color = ColorSettings{o.ocio_config, o.display, o.view};
    os.bits = o.bits;
    os.exr_half = !o.exr_float;
    { DisplayTransform check(os.color); }

    Renderer renderer(scene, rs);
    const ImageSize size = renderer.image_size();
    log_info("{}: {} triangles in {} instances, {} lights, camera {}/{}{}, {}x{}", o.input,
             scene.instanced_triangle_count(), scene.instances.size(), scene.lights.size(), o.camera,
             scene.cameras.size(), scene.cameras[size_t(o.camera)].is_default ? " (default)" : "", size.width,
             size.height);
    RenderStats stats;
    Film film = renderer.render(&stats);

    const auto t_write = Clock::now();
    const uint64_t rays = stats.rays.total();
    const double mrays = stats.render_seconds > 0 ? double(rays) / stats.render_seconds * 1e-6 : 0.0;
    std::string summary = fmt::format(
        "time: load {:.3f}s, build {:.3f}s, render {:.3f}s | rays: {} camera, {} shadow, {} reflection, "
        "{} refraction, {} total, {:.2f} Mrays/s on {} threads",
        load_s, stats.build_seconds, stats.render_seconds, stats.rays.camera, stats.rays.shadow,
        stats.rays.reflection, stats.rays.refraction, rays, mrays, stats.threads);
    os.metadata["whitted:commandLine"] = cmdline;
    os.metadata["whitted:version"] = WHITTED_VERSION;
    os.metadata["whitted:stats"] = summary;
    os.metadata["Software"] = std::string("whitted ") + WHITTED_VERSION;
    write_image(film, o.output, os);
    const double write_s = seconds_since(t_write);

    std::fprintf(stderr,
                 "whitted: wrote %s (%dx%d)\n"
                 "  time   load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
                 "  rays   camera %llu  shadow %llu  reflection %llu  refraction %llu  total %llu\n"
                 "  speed  %.2f Mrays/s on %d threads\n",
                 o.output.c_str(), film.width(), film.height(), load_s, stats.build_seconds, stats.render_seconds,
                 write_s, (unsigned long long)stats.rays.camera, (unsigned long long)stats.rays.shadow,
                 (unsigned long long)stats.rays.reflection, (unsigned long long)stats.rays.refraction,
                 (unsigned long long)rays, mrays, stats.threads);
    return 0;
}

int run_info(const std::string& input, int scene_index, bool textures) {
    ImportOptions io;
    io.scene_index = scene_index;
    io.load_textures = textures;
    Scene scene = load_scene(input, io);
    std::fputs(describe_scene(scene).c_str(), stdout);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"whitted: a Whitted-style (1980) recursive ray tracer for glTF 2.0 scenes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("whitted ") + WHITTED_VERSION);
    std::string log_level = "info";
    app.add_option("--log-level", log_level, "Messages to print: debug, info, warning, error, off")
        ->check(CLI::IsMember({"debug", "info", "warning", "error", "off"}))
        ->capture_default_str();

    // whitted render
    RenderOptions ro;
    CLI::App* render = app.add_subcommand("render", "Render a scene to an image");
    render->add_option("scene", ro.input, "Scene file (.gltf or .glb)")->required();
    render->add_option("-o,--output", ro.output,
                       "Output image; the extension picks the format: .exr (scene-linear, AOVs), "
                       ".png/.jpg/.tif (display-referred through OCIO)")
        ->capture_default_str();
    render->add_option("--width", ro.width, "Image width in pixels (0 = from --height and the camera aspect, else 640)")
        ->check(CLI::Range(0, 32768))->capture_default_str();
    render->add_option("--height", ro.height, "Image height in pixels (0 = from the width and the camera aspect)")
        ->check(CLI::Range(0, 32768))->capture_default_str();
    render->add_option("--camera", ro.camera, "Camera index (see `whitted info`)")->capture_default_str();
    render->add_option("--scene", ro.scene, "glTF scene index (-1 = the file's default scene)")->capture_default_str();
    render->add_option("--max-depth", ro.max_depth, "Maximum depth of the ray tree (0 = no reflection/refraction)")
        ->check(CLI::Range(0, 64))->capture_default_str();
    render->add_option("--background", ro.background, "Radiance of rays that hit nothing: r,g,b or gray (linear)")
        ->capture_default_str();
    render->add_option("--ambient", ro.ambient, "Ambient light Ia: r,g,b or gray (linear)")->capture_default_str();
    render->add_option("--exposure", ro.exposure, "Exposure in stops: radiance is scaled by 2^exposure")
        ->capture_default_str();
    render->add_flag("--fresnel", ro.fresnel, "Weight reflection and transmission with Schlick's Fresnel term");
    render->add_flag("--refract-thin", ro.refract_thin,
                     "Refract through transmissive materials without KHR_materials_volume (classic glass)");
    render->add_option("--mirror-cutoff", ro.mirror_cutoff,
                       "Roughness at which mirror reflection has faded to 0 (see docs/materials.md)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    render->add_option("--aov", ro.aovs, "Extra EXR channels: depth, normal, albedo, primid, instid, all")
        ->delimiter(',');
    render->add_option("--crop", ro.crop, "Render only the region x0,y0,x1,y1 (pixels, x1/y1 exclusive)");
    render->add_option("--threads", ro.threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    render->add_option("--tile-size", ro.tile_size, "Tile size in pixels")->check(CLI::Range(1, 4096))
        ->capture_default_str();
    render->add_option("--accel", ro.accel, "Acceleration structure: embree")->capture_default_str();
    render->add_flag("--robust", ro.robust, "Embree robust mode (RTC_SCENE_FLAG_ROBUST)");
    render->add_option("--ocio-config", ro.ocio_config, "OpenColorIO config (default: $OCIO, else the bundled one)");
    render->add_option("--display", ro.display, "OCIO display (default: the config's default)");
    render->add_option("--view", ro.view, "OCIO view: Standard, ACES 1.0 SDR-video, Raw")->capture_default_str();
    render->add_option("--bits", ro.bits, "Bits per channel for PNG/TIFF: 8 or 16 (0 = format default)")
        ->check(CLI::IsMember({0, 8, 16}))->capture_default_str();
    render->add_flag("--exr-float", ro.exr_float, "Write EXR beauty as 32-bit float instead of half");
    render->add_flag("--no-progress", ro.no_progress, "Do not draw the progress bar");
    render->add_option("--max-memory", ro.max_memory_gb, "Refuse scenes whose data would exceed this many GiB")
        ->check(CLI::PositiveNumber)->capture_default_str();

    // whitted info
    std::string info_input;
    int info_scene = -1;
    bool info_no_textures = false;
    CLI::App* info = app.add_subcommand("info", "Print what a scene file contains after import");
    info->add_option("scene", info_input, "Scene file (.gltf or .glb)")->required();
    info->add_option("--scene", info_scene, "glTF scene index (-1 = the file's default scene)")->capture_default_str();
    info->add_flag("--no-textures", info_no_textures, "Skip decoding images");

    // whitted bench <name>: benchmarks print figures and write CSV/plots (docs/performance.md).
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print figures, write CSV and plots");
    bench->require_subcommand(1);
    std::vector<app::Command> commands;
    // Each benchmark module registers itself here (one line each):

    // Global options (--log-level) may also follow the subcommand.
    render->fallthrough();
    info->fallthrough();
    bench->fallthrough();
    for (app::Command& c : commands) c.app->fallthrough();

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::Success& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "whitted: error: %s (see whitted --help)\n", e.what());
        return 2;
    }

    try {
        set_log_level(parse_log_level(log_level));
        if (render->parsed()) return run_render(ro, command_line(argc, argv));
        if (info->parsed()) return run_info(info_input, info_scene, !info_no_textures);
        for (app::Command& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const Error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "whitted: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
