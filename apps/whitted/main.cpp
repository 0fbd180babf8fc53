// whitted: the command-line front end (`whitted render`, `whitted info`).
//
// Errors from bad input or bad flags end in exactly one line on stderr and a non-zero exit code:
// 2 for command-line errors, 1 for everything else.
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <unistd.h>

#include "benchmarks/bench_commands.h"
#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "renderer/accel/accelerator.h"
#include "renderer/core/error.h"
#include "renderer/core/log.h"
#include "renderer/integrator/render.h"
#include "renderer/output/image_output.h"

namespace {

using namespace whitted;
using Clock = std::chrono::steady_clock;

// SIGINT/SIGTERM during `render`: nothing is written before the image is complete, so the first
// signal ends the process at once, except while the image is being written: that write (atomic,
// through a temporary file) finishes and the run then exits with 128 + signal. A second SIGINT
// exits at once in every case, removing the temporary file of an unfinished write.
std::atomic<int> g_signal_count{0};
std::atomic<int> g_last_signal{0};
std::atomic<bool> g_writing{false};

extern "C" void on_interrupt(int sig) {
    g_last_signal.store(sig);
    if (g_signal_count.fetch_add(1) == 0 && g_writing.load()) return;
    remove_partial_output();
    static const char message[] = "\nwhitted: interrupted: no image written\n";
    const ssize_t ignored = ::write(STDERR_FILENO, message, sizeof(message) - 1);
    (void)ignored;
    ::_exit(128 + sig);
}

void install_interrupt_handlers() {
    struct sigaction sa {};
    sa.sa_handler = &on_interrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

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
        else if (n == "aa_samples" || n == "aasamples") a.aa_samples = true;
        else if (n == "all") a = AovSet{true, true, true, true, true, true};
        else
            throw Error(fmt::format(
                "--aov: unknown AOV '{}' (available: depth, normal, albedo, primid, instid, aa_samples, all)", n));
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
    std::string precision, bv;  ///< in-house BVH options given as flags (appended to the --accel spec)
    std::vector<std::string> aovs;
    std::string aa = "adaptive", filter = "box";
    float aa_threshold = AaSettings{}.threshold;
    int aa_depth = AaSettings{}.depth, spp = AaSettings{}.spp;
    float exposure = 0.f, mirror_cutoff = 0.3f, min_weight = 1.f / 255.f;
    bool fresnel = false, refract_thin = false, robust = true, no_progress = false, exr_float = false;
    bool no_specialize = false;
    double max_memory_gb = 8.0;
    bool allow_outside_uris = false;
};

/// `--precision` and `--bv` are shorthands for the accelerator spec's options of the same names
/// (`--accel bvh --precision double` == `--accel bvh:precision=double`): each given one is appended
/// to the spec, whose parser rejects it, naming the backend, where it does not apply.
std::string with_spec_options(std::string spec, std::initializer_list<std::pair<const char*, std::string>> options) {
    for (const auto& [key, value] : options) {
        if (value.empty()) continue;
        spec += spec.find(':') == std::string::npos ? ':' : ',';
        spec += fmt::format("{}={}", key, value);
    }
    return spec;
}

/// Scene-file render settings fill every option the command line did not give (`given(flag)`);
/// flags always win. A relative output path is taken relative to the scene file (as pbrt does).
template <class Given>
void apply_scene_settings(RenderOptions& o, const SceneRenderSettings& s, const std::string& scene_path,
                          Given&& given) {
    auto color_text = [](const Color& c) { return fmt::format("{},{},{}", c.x, c.y, c.z); };
    if (s.width && !given("--width")) o.width = *s.width;
    if (s.height && !given("--height")) o.height = *s.height;
    if (s.camera && !given("--camera")) o.camera = *s.camera;
    if (s.aa && !given("--aa")) o.aa = *s.aa;
    if (s.aa_threshold && !given("--aa-threshold")) o.aa_threshold = *s.aa_threshold;
    if (s.aa_depth && !given("--aa-depth")) o.aa_depth = *s.aa_depth;
    if (s.spp && !given("--spp")) o.spp = *s.spp;
    if (s.max_depth && !given("--max-depth")) o.max_depth = *s.max_depth;
    if (s.min_weight && !given("--min-weight")) o.min_weight = *s.min_weight;
    if (s.background && !given("--background")) o.background = color_text(*s.background);
    if (s.ambient && !given("--ambient")) o.ambient = color_text(*s.ambient);
    if (s.exposure && !given("--exposure")) o.exposure = *s.exposure;
    if (s.fresnel && !given("--fresnel")) o.fresnel = *s.fresnel;
    if (s.view && !given("--view")) o.view = *s.view;
    if (s.display && !given("--display")) o.display = *s.display;
    if (s.output && !given("--output")) {
        std::filesystem::path out(*s.output);
        o.output = out.is_absolute() ? out.string() : (std::filesystem::path(scene_path).parent_path() / out).string();
    }
}

template <class Given>
int run_render(RenderOptions o, const std::string& cmdline, Given&& given) {
    install_interrupt_handlers();
    const auto t_load = Clock::now();
    ImportOptions io;
    io.scene_index = o.scene;
    io.max_memory = size_t(o.max_memory_gb * double(size_t(1) << 30));
    io.allow_outside_uris = o.allow_outside_uris;
    set_accelerator_memory_limit(io.max_memory);
    Scene scene = load_scene(o.input, io);
    const double load_s = seconds_since(t_load);
    for (const std::string& w : scene.warnings) log_warning("{}: {}", o.input, w);
    apply_scene_settings(o, scene.settings, o.input, given);
    if (!(o.min_weight >= 0.f && o.min_weight <= 1.f))
        throw Error(fmt::format("min_weight {} is out of range (expected 0 to 1)", o.min_weight));

    RenderSettings rs;
    rs.width = o.width;
    rs.height = o.height;
    rs.camera = o.camera;
    rs.integrator.max_depth = o.max_depth;
    rs.integrator.background = parse_color(o.background, "--background");
    rs.integrator.ambient = parse_color(o.ambient, "--ambient");
    rs.integrator.fresnel = o.fresnel;
    rs.integrator.min_weight = o.min_weight;
    rs.integrator.specialize = !o.no_specialize;
    rs.mapping.refract_thin = o.refract_thin;
    rs.mapping.mirror_roughness_cutoff = o.mirror_cutoff;
    rs.exposure = std::exp2(o.exposure);
    rs.tile_size = o.tile_size;
    rs.threads = o.threads;
    if (!o.crop.empty()) rs.crop = parse_crop(o.crop);
    rs.aovs = parse_aovs(o.aovs);
    rs.aa.mode = parse_aa_mode(o.aa);
    rs.aa.threshold = o.aa_threshold;
    rs.aa.depth = o.aa_depth;
    rs.aa.spp = o.spp;
    rs.aa.filter = parse_pixel_filter(o.filter);
    rs.accel = with_spec_options(o.accel, {{"precision", o.precision}, {"bv", o.bv}});
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
    // What the scene uses and what the renderer skips (docs/performance.md).
    {
        std::istringstream analysis(describe_analysis(scene, renderer.view().analysis()));
        // Per-material lines, and per-light lines of scenes with many lights, at debug level.
        const bool many_lights = scene.lights.size() > 16;
        for (std::string l; std::getline(analysis, l);) {
            if (l.rfind("analysis material[", 0) == 0 || (many_lights && l.rfind("analysis light[", 0) == 0))
                log_debug("{}", l);
            else
                log_info("{}", l);
        }
        log_info("kernel: {}", kernel_name(renderer.kernel()));
    }
    RenderStats stats;
    Film film = renderer.render(&stats);

    const auto t_write = Clock::now();
    const uint64_t rays = stats.rays.total();
    const double mrays = stats.render_seconds > 0 ? double(rays) / stats.render_seconds * 1e-6 : 0.0;
    const double subdivided = stats.pixels ? double(stats.pixels_subdivided) / double(stats.pixels) : 0.0;
    std::string summary = fmt::format(
        "time: load {:.3f}s, build {:.3f}s, render {:.3f}s | rays: {} camera, {} shadow, {} reflection, "
        "{} refraction, {} aov probe, {} total, {:.2f} Mrays/s on {} threads | aa: {} ({:.3f} camera rays/pixel, "
        "{:.1f}% pixels subdivided)",
        load_s, stats.build_seconds, stats.render_seconds, stats.rays.camera, stats.rays.shadow,
        stats.rays.reflection, stats.rays.refraction, stats.rays.aov_probe, rays, mrays, stats.threads, o.aa,
        stats.pixels ? double(stats.rays.camera) / double(stats.pixels) : 0.0, 100.0 * subdivided);
    os.metadata["whitted:commandLine"] = cmdline;
    os.metadata["whitted:version"] = WHITTED_VERSION;
    os.metadata["whitted:stats"] = summary;
    os.metadata["Software"] = std::string("whitted ") + WHITTED_VERSION;
    g_writing.store(true);
    write_image(film, o.output, os);
    g_writing.store(false);
    if (g_signal_count.load() > 0) {
        std::fprintf(stderr, "whitted: interrupted: wrote %s before exiting\n", o.output.c_str());
        return 128 + g_last_signal.load();
    }
    const double write_s = seconds_since(t_write);

    std::fprintf(stderr,
                 "whitted: wrote %s (%dx%d)\n"
                 "  time   load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
                 "  rays   camera %llu  shadow %llu  reflection %llu  refraction %llu  total %llu\n"
                 "  skip   %s; shadow rays not cast: %llu unreached, %llu facing away, %llu with a zero term; "
                 "secondary rays below --min-weight %g: %llu\n"
                 "  speed  %.2f Mrays/s on %d threads\n"
                 "  aa     %s: %.3f camera rays/pixel, %.1f%% pixels subdivided\n",
                 o.output.c_str(), film.width(), film.height(), load_s, stats.build_seconds, stats.render_seconds,
                 write_s, (unsigned long long)stats.rays.camera, (unsigned long long)stats.rays.shadow,
                 (unsigned long long)stats.rays.reflection, (unsigned long long)stats.rays.refraction,
                 (unsigned long long)rays, kernel_name(renderer.kernel()).c_str(),
                 (unsigned long long)stats.rays.shadow_skipped_unreached,
                 (unsigned long long)stats.rays.shadow_skipped_facing,
                 (unsigned long long)stats.rays.shadow_skipped_zero, double(o.min_weight),
                 (unsigned long long)stats.rays.secondary_skipped_cutoff, mrays, stats.threads, o.aa.c_str(),
                 stats.pixels ? double(stats.rays.camera) / double(stats.pixels) : 0.0, 100.0 * subdivided);
    return 0;
}

int run_info(const std::string& input, int scene_index, bool textures, bool allow_outside_uris) {
    ImportOptions io;
    io.scene_index = scene_index;
    io.load_textures = textures;
    io.allow_outside_uris = allow_outside_uris;
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
    render->add_option("scene", ro.input, "Scene file (.gltf, .glb, or a .json scene file: docs/scene-format.md)")->required();
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
    render->add_option("--min-weight", ro.min_weight,
                       "Adaptive tree depth (Hall & Greenberg 1983): skip reflected/refracted rays whose accumulated "
                       "weight is below this (default 1/255; 0 = trace to --max-depth)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    render->add_flag("--no-specialize", ro.no_specialize,
                     "Use the general shading kernel instead of the one the scene needs (to measure the gain)");
    render->add_flag("--fresnel", ro.fresnel, "Weight reflection and transmission with Schlick's Fresnel term");
    render->add_flag("--refract-thin", ro.refract_thin,
                     "Refract through transmissive materials without KHR_materials_volume (classic glass)");
    render->add_option("--mirror-cutoff", ro.mirror_cutoff,
                       "Roughness at which mirror reflection has faded to 0 (see docs/materials.md)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    render->add_option("--aov", ro.aovs, "Extra EXR channels: depth, normal, albedo, primid, instid, aa_samples, all")
        ->delimiter(',');
    render->add_option("--aa", ro.aa, "Anti-aliasing: center, corners, adaptive, stratified (docs/antialiasing.md)")
        ->check(CLI::IsMember({"center", "corners", "adaptive", "stratified"}))->capture_default_str();
    render->add_option("--aa-threshold", ro.aa_threshold,
                       "adaptive: split a square when its corners differ by more than this in display-referred "
                       "sRGB values (max channel difference); negative = always split")
        ->capture_default_str();
    render->add_option("--aa-depth", ro.aa_depth, "adaptive: maximum subdivision depth (sub-squares of 1/2^depth pixel)")
        ->check(CLI::Range(0, 8))->capture_default_str();
    render->add_option("--spp", ro.spp, "stratified: samples per pixel, a square number k*k")
        ->check(CLI::Range(1, 4096))->capture_default_str();
    render->add_option("--filter", ro.filter, "stratified: pixel filter, box or tent (radius 1 pixel)")
        ->check(CLI::IsMember({"box", "tent"}))->capture_default_str();
    render->add_option("--crop", ro.crop, "Render only the region x0,y0,x1,y1 (pixels, x1/y1 exclusive)");
    render->add_option("--threads", ro.threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    render->add_option("--tile-size", ro.tile_size, "Tile size in pixels")->check(CLI::Range(1, 4096))
        ->capture_default_str();
    render->add_option("--accel", ro.accel,
                       "Acceleration structure: embree, bvh, grid, octree, kdop, brute; options after a colon, "
                       "e.g. bvh:precision=double,bv=sphere (docs/accelerators.md)")->capture_default_str();
    render->add_option("--precision", ro.precision,
                       "In-house BVH and brute force: trace in float or double (the reference), same as "
                       "--accel bvh:precision=...")->check(CLI::IsMember({"float", "double"}));
    render->add_option("--bv", ro.bv,
                       "In-house BVH bounding volume: aabb or sphere (the seed's bounding spheres), same as "
                       "--accel bvh:bv=...")->check(CLI::IsMember({"aabb", "sphere"}));
    render->add_flag("--robust,!--no-robust", ro.robust,
                     "Embree robust mode (RTC_SCENE_FLAG_ROBUST, the default): no light leaks at shared edges; "
                     "--no-robust is 3-8% faster and leaks a few % of rays aimed at edges and vertices");
    render->add_option("--ocio-config", ro.ocio_config, "OpenColorIO config (default: $OCIO, else the bundled one)");
    render->add_option("--display", ro.display, "OCIO display (default: the config's default)");
    render->add_option("--view", ro.view, "OCIO view: Standard, ACES 1.0 SDR-video, Raw")->capture_default_str();
    render->add_option("--bits", ro.bits, "Bits per channel for PNG/TIFF: 8 or 16 (0 = format default)")
        ->check(CLI::IsMember({0, 8, 16}))->capture_default_str();
    render->add_flag("--exr-float", ro.exr_float, "Write EXR beauty as 32-bit float instead of half");
    render->add_flag("--no-progress", ro.no_progress, "Do not draw the progress bar");
    render->add_option("--max-memory", ro.max_memory_gb, "Refuse scenes whose data would exceed this many GiB")
        ->check(CLI::PositiveNumber)->capture_default_str();
    render->add_flag("--allow-outside-uris", ro.allow_outside_uris,
                     "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");

    // whitted info
    std::string info_input;
    int info_scene = -1;
    bool info_no_textures = false, info_allow_outside_uris = false;
    CLI::App* info = app.add_subcommand("info", "Print what a scene file contains after import");
    info->add_option("scene", info_input, "Scene file (.gltf, .glb or .json)")->required();
    info->add_option("--scene", info_scene, "glTF scene index (-1 = the file's default scene)")->capture_default_str();
    info->add_flag("--no-textures", info_no_textures, "Skip decoding images");
    info->add_flag("--allow-outside-uris", info_allow_outside_uris,
                   "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");

    // whitted bench <name>: benchmarks print figures and write CSV/plots (docs/performance.md).
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print figures, write CSV and plots");
    bench->require_subcommand(1);
    std::vector<app::Command> commands;
    // Each benchmark module registers itself here (one line each; benchmarks/bench_commands.h):
    commands.push_back(app::register_bench_aa(*bench));
    commands.push_back(app::register_bench_accel(*bench));
    commands.push_back(app::register_bench_skip(*bench));
    commands.push_back(app::register_bench_stability(*bench));

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
        if (render->parsed())
            return run_render(ro, command_line(argc, argv),
                              [&](const char* flag) { return render->count(flag) > 0; });
        if (info->parsed()) return run_info(info_input, info_scene, !info_no_textures, info_allow_outside_uris);
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
