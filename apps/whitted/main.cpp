// whitted: the command-line front end (`whitted render`, `whitted info`).
//
// Errors from bad input or bad flags end in exactly one line on stderr and a non-zero exit code:
// 2 for command-line errors, 1 for everything else.
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <unistd.h>

#include "benchmarks/bench_commands.h"
#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "renderer/accel/accelerator.h"
#include "renderer/core/error.h"
#include "renderer/core/huge_pages.h"
#include "renderer/core/image_files_display.h"
#include "renderer/core/image_files_exr.h"
#include "renderer/core/log.h"
#include "renderer/integrator/render.h"
#include "renderer/output/image_output.h"
#include "renderer/session/frame_render.h"
#include "renderer/session/mpi_frame.h"
#include "renderer/session/tile_job.h"

namespace {

using namespace whitted;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// SIGINT/SIGTERM during `render` (docs/distributed.md, "Interruption and resume"): while tiles
// render, the first signal stops handing out new ones; the tiles in flight finish and the image is
// written with what is done (missing tiles 0, listed in its metadata) plus a checkpoint for
// --resume, then the run exits with 128 + signal. Before rendering starts it ends the process at
// once; during a write, the write (atomic, through a temporary file) finishes first. A second
// signal exits at once in every case, removing the temporary file of an unfinished write and
// leaving earlier files as they were.
std::atomic<int> g_signal_count{0};
std::atomic<int> g_last_signal{0};
std::atomic<bool> g_writing{false};
std::atomic<bool> g_rendering{false};
std::atomic<bool> g_stop{false};
// Under MPI, once the ranks render together an error on one rank ends them all (MPI_Abort):
// the others would wait for it forever.
std::atomic<bool> g_mpi_running{false};
whitted::MpiSession* g_mpi = nullptr;

extern "C" void on_interrupt(int sig) {
    g_last_signal.store(sig);
    const bool first = g_signal_count.fetch_add(1) == 0;
    if (first && (g_writing.load() || g_rendering.load())) {
        g_stop.store(true);
        if (!g_writing.load()) {
            static const char message[] =
                "\nwhitted: interrupted: finishing the tiles in flight, then writing what is done "
                "(interrupt again to quit at once)\n";
            const ssize_t ignored = ::write(STDERR_FILENO, message, sizeof(message) - 1);
            (void)ignored;
        }
        return;
    }
    remove_partial_output();
    static const char message[] = "\nwhitted: interrupted: exiting at once; earlier files are left as they were\n";
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
    // Under mpirun, ^C and SIGTERM end the whole job at once; SIGUSR1 it passes on to the ranks
    // and leaves the job running: `kill -USR1 <mpirun>` stops a distributed render gracefully.
    if (g_mpi) sigaction(SIGUSR1, &sa, nullptr);
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string command_line(int argc, char** argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) {
        if (i) s += ' ';
        s += argv[i];
    }
    return s;
}

/// Shown as a flag's default: "0.05" for a gray, "r,g,b" otherwise.
std::string color_text(const Color& c) {
    return c.x == c.y && c.y == c.z ? fmt::format("{}", c.x) : fmt::format("{},{},{}", c.x, c.y, c.z);
}

/// What `whitted render` collects: the library's settings, which the flags set directly, and the
/// few flags that are only other spellings of them.
struct RenderCommand {
    std::string input;                          ///< scene file
    std::string output = "whitted.png";         ///< image file; the extension picks the format
    ImportOptions import;                       ///< glTF scene index, outside URIs
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
};

const Clock::time_point g_process_start = Clock::now();

/// `--tile-log`: one row per tile rendered by this process, with the run's start-up time (process
/// start to the first tile) and the bytes a tile's message to MPI rank 0 takes.
void write_tile_log(const std::string& path, const FrameResult& frame, const std::string& scene, int tile_size,
                    int threads, double startup) {
    std::ofstream out(path);
    if (!out) throw Error(fmt::format("--tile-log: cannot write {}", path));
    out << "scene,tile_size,threads,startup,tile,x0,y0,x1,y1,seconds,bytes,cost\n";
    for (size_t i = 0; i < frame.tiles.size(); ++i) {
        if (frame.tile_seconds[i] <= 0.0) continue;
        const TileRect& t = frame.tiles[i];
        const size_t bytes = tile_message_bytes(t, frame.film.aovs);
        const double cost = frame.tile_cost.empty() ? 0.0 : frame.tile_cost[i];
        out << fmt::format("{},{},{},{:.6f},{},{},{},{},{},{:.9f},{},{:.0f}\n", scene, tile_size, threads, startup, i,
                           t.x0, t.y0, t.x1, t.y1, frame.tile_seconds[i], bytes, cost);
    }
    if (!out) throw Error(fmt::format("--tile-log: cannot write {}", path));
}

/// The environment flags (docs/environment.md), shared by `render` and `info`.
void add_environment_options(CLI::App* app, ImportOptions& io) {
    app->add_option("--environment", io.environment,
                    "Lat-long HDR map around the scene (a file, or a bundled name: studio, city, courtyard, "
                    "forest, interior, sunset); replaces the scene file's");
    app->add_option_function<float>("--env-rotate", [&io](const float& deg) { io.environment_rotation = deg; },
                                    "Turn the environment about +Y by this many degrees");
    app->add_option_function<float>("--env-exposure", [&io](const float& stops) { io.environment_exposure = stops; },
                                    "Scale the environment's radiance by 2^stops");
    app->add_option("--env-lights", io.environment_lights,
                    "Directional lights extracted from the environment's brightest regions (0 = all of its light "
                    "is ambient)")->check(CLI::Range(0, 4096))->capture_default_str();
    app->add_flag("--no-environment", io.no_environment, "No environment, whatever the scene file names");
}

/// The output flags (colour pipeline, bits, EXR precision), shared by `render` and `merge`.
void add_output_options(CLI::App* app, OutputSettings& out) {
    app->add_option("--ocio-config", out.color.config, "OpenColorIO config (default: $OCIO, else the bundled one)");
    app->add_option("--display", out.color.display, "OCIO display (default: the config's default)");
    app->add_option("--view", out.color.view, "OCIO view: Standard, ACES 1.0 SDR-video, Raw")->capture_default_str();
    app->add_option("--bits", out.bits, "Bits per channel for PNG/TIFF: 8 or 16 (0 = format default)")
        ->check(CLI::IsMember({0, 8, 16}))->capture_default_str();
    app->add_flag_function("--exr-float", [&out](std::int64_t) { out.exr_half = false; },
                           "Write EXR beauty as 32-bit float instead of half");
    app->add_option("--exr-compression", out.exr_compression,
                    "EXR compression, lossless: none, rle, zips, zip, piz; zip/zips take a zlib level, e.g. zip:6 "
                    "(zip = zip:1; none writes fastest, at about 3x the bytes of zip for a float beauty)")
        ->check([](const std::string& v) { return exr_compression_error(v); })
        ->capture_default_str();
    app->add_option("--tiff-compression", out.tiff_compression,
                    "TIFF compression, lossless: zip (Deflate with the horizontal predictor; zip:N, N = 1-12) or "
                    "none (a 16-bit TIFF about 1.3x faster, at about 7x the bytes)")
        ->check([](const std::string& v) { return tiff_compression_error(v); })
        ->capture_default_str();
}

/// `whitted merge`: the parts of a tile job assembled and written like `render` writes a frame.
int run_merge(const std::vector<std::string>& parts, const std::string& output, OutputSettings os,
              const std::string& cmdline) {
    { DisplayTransform check(os.color); }
    std::map<std::string, std::string> meta;
    const Film film = merge_parts(parts, &meta);
    for (const auto& [key, value] : meta) os.metadata[key] = value;
    os.metadata["whitted:commandLine"] = cmdline;
    os.metadata["whitted:version"] = WHITTED_VERSION;
    write_image(film, output, os);
    std::fprintf(stderr, "whitted: wrote %s (%dx%d) from %zu parts\n", output.c_str(), film.width(), film.height(),
                 parts.size());
    return 0;
}

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

int run_render(RenderCommand c, const std::string& cmdline, const SettingGiven& given, MpiSession* mpi) {
    const bool root = !mpi || mpi->rank() == 0;
    if (root) {
        install_interrupt_handlers();
    } else {
        // mpirun passes ^C and SIGTERM on to every rank: rank 0 decides (no new tiles, write what
        // is done); the others finish the tiles they hold and are then told there are no more.
        std::signal(SIGINT, SIG_IGN);
        std::signal(SIGTERM, SIG_IGN);
        std::signal(SIGUSR1, SIG_IGN);
    }
    // The scene file's settings fill what the flags did not set.
    RenderSettings& rs = c.render;
    OutputSettings& os = c.out;
    Scene scene;
    double load_s = 0.0;
    SettingList identity;
    std::unique_ptr<Renderer> renderer_ptr;
    std::string setup_error;
    try {
        const auto t_load = Clock::now();
        c.import.max_memory = size_t(c.max_memory_gb * double(size_t(1) << 30));
        set_accelerator_memory_limit(c.import.max_memory);
        scene = load_scene(c.input, c.import);
        load_s = seconds_since(t_load);
        for (const std::string& w : scene.warnings) log_warning("{}: {}", c.input, w);

        // The scene file's settings fill what the flags did not set.
        apply_scene_settings(scene.settings, rs, given);
        apply_scene_output_settings(scene.settings, c.input, c.output, os, given);
        if (!(rs.integrator.min_weight >= 0.f && rs.integrator.min_weight <= 1.f))
            throw Error(fmt::format("min_weight {} is out of range (expected 0 to 1)", rs.integrator.min_weight));
        rs.accel = with_spec_options(rs.accel, {{"precision", c.precision}, {"bv", c.bv}});

        // Resolve the color pipeline before the (long) render so bad flags fail fast.
        { DisplayTransform check(os.color); }

        // What the pixels depend on: recorded by checkpoints and tile-job parts, checked by --resume
        // and `whitted merge`.
        identity = {{"version", WHITTED_VERSION}, {"scene", c.input + " (" + file_identity(c.input) + ")"}};
        for (auto& kv : describe_import_options(c.import)) identity.push_back(kv);
        for (auto& kv : describe_image_settings(rs)) identity.push_back(kv);
        if (!c.tile_job.empty()) {
            const TileJob job = parse_tile_job(c.tile_job);
            if (fs::path(c.output).extension() != ".exr")
                throw Error(fmt::format("--tile-job writes an EXR part (merge it with `whitted merge`): got -o {}", c.output));
            if (rs.camera < 0 || size_t(rs.camera) >= scene.cameras.size())
                throw Error(fmt::format("--camera {}: the scene has {} camera(s)", rs.camera, scene.cameras.size()));
            const ImageSize full = resolve_image_size(scene.cameras[size_t(rs.camera)], rs.width, rs.height);
            const PixelWindow frame = rs.crop.value_or(PixelWindow{0, 0, full.width, full.height});
            rs.crop = tile_job_window(frame, job);
            for (const auto& [key, value] : tile_job_metadata(job, frame, identity)) os.metadata[key] = value;
            os.exr_half = false;  // exact: the merged frame is bit-identical to a one-piece render
        }
        renderer_ptr = std::make_unique<Renderer>(scene, rs);
    } catch (const Error& e) {
        if (!mpi || mpi->size() == 1) throw;
        setup_error = e.what();
    }
    // The ranks agree on the set-up; rank 0, when its own succeeded, agrees once it serves tiles
    // (MpiTileServer), rendering its own meanwhile.
    if (mpi && mpi->size() > 1 && (!root || !setup_error.empty()))
        if (const std::optional<std::string> failed = mpi->agree_setup(setup_error)) {
            if (!failed->empty()) std::fprintf(stderr, "whitted: error: %s\n", failed->c_str());
            return 1;
        }
    const Renderer& renderer = *renderer_ptr;
    if (mpi && mpi->size() > 1 && !root) {  // a worker rank: tiles for rank 0, nothing else
        g_mpi_running.store(true);
        serve_mpi_worker(*mpi, renderer);
        return 0;
    }
    const ImageSize size = renderer.image_size();
    log_info("{}: {} triangles in {} instances, {} lights, camera {}/{}{}, {}x{}", c.input,
             scene.instanced_triangle_count(), scene.instances.size(), scene.lights.size(), rs.camera,
             scene.cameras.size(), scene.cameras[size_t(rs.camera)].is_default ? " (default)" : "", size.width,
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
    FrameOptions fo;
    fo.identity = identity;
    fo.identity.emplace_back("window", fmt::format("{},{},{},{}", renderer.window().x0, renderer.window().y0,
                                                   renderer.window().x1, renderer.window().y1));
    fo.checkpoint_path = c.checkpoint_file.empty() ? checkpoint_path_for(c.output) : c.checkpoint_file;
    fo.checkpoint_seconds = c.checkpoint_seconds;
    fo.resume = c.resume;
    fo.stop = &g_stop;
    fo.progress = rs.progress;
    fo.order = c.tile_order;
    g_rendering.store(true);
    std::optional<MpiTileServer> server;
    if (mpi && mpi->size() > 1) {
        server.emplace(*mpi, renderer);
        g_mpi_running.store(true);
        log_info("MPI: {} ranks, {} threads each", mpi->size(), renderer.settings().threads);
    }
    const double startup = seconds_since(g_process_start);
    FrameResult frame = render_frame(renderer, fo, server ? &*server : nullptr);
    g_mpi_running.store(false);
    // Every tile is in: MPI ends (the other ranks exit) while this rank writes the image.
    if (mpi) mpi->finish();
    g_rendering.store(false);
    const RenderStats& stats = frame.stats;
    const Film& film = frame.film;
    if (!c.tile_log.empty())
        write_tile_log(c.tile_log, frame, fs::path(c.input).filename().string(), rs.tile_size, stats.threads, startup);
    const std::vector<size_t> missing = frame.missing();
    if (!missing.empty()) {
        os.metadata["whitted:missingTiles"] = describe_tiles(frame.tiles, missing);
        os.metadata["whitted:incomplete"] =
            fmt::format("{} of {} tiles missing (0 in the image); continue with --resume", missing.size(),
                        frame.tiles.size());
    }
    const char* aa_name = aa_mode_name(rs.aa.mode);

    const auto t_write = Clock::now();
    const uint64_t rays = stats.rays.total();
    const double mrays = stats.render_seconds > 0 ? double(rays) / stats.render_seconds * 1e-6 : 0.0;
    const double subdivided = stats.pixels ? double(stats.pixels_subdivided) / double(stats.pixels) : 0.0;
    std::string summary = fmt::format(
        "time: load {:.3f}s, build {:.3f}s, render {:.3f}s | rays: {} camera, {} shadow, {} reflection, "
        "{} refraction, {} aov probe, {} total, {:.2f} Mrays/s on {} threads | aa: {} ({:.3f} camera rays/pixel, "
        "{:.1f}% pixels subdivided)",
        load_s, stats.build_seconds, stats.render_seconds, stats.rays.camera, stats.rays.shadow,
        stats.rays.reflection, stats.rays.refraction, stats.rays.aov_probe, rays, mrays, stats.threads, aa_name,
        stats.pixels ? double(stats.rays.camera) / double(stats.pixels) : 0.0, 100.0 * subdivided);
    os.metadata["whitted:commandLine"] = cmdline;
    os.metadata["whitted:version"] = WHITTED_VERSION;
    os.metadata["whitted:stats"] = summary;
    os.metadata["Software"] = std::string("whitted ") + WHITTED_VERSION;
    g_writing.store(true);
    write_image(film, c.output, os);
    g_writing.store(false);
    if (!missing.empty()) {
        std::fprintf(stderr,
                     "whitted: interrupted: wrote %s with %zu of %zu tiles (the missing ones are 0 and listed in its "
                     "metadata) and the checkpoint %s; continue with --resume\n",
                     c.output.c_str(), frame.tiles.size() - missing.size(), frame.tiles.size(),
                     fo.checkpoint_path.c_str());
        return 128 + g_last_signal.load();
    }
    // The finished frame is written: its checkpoint is no longer needed.
    std::error_code ec;
    fs::remove(fo.checkpoint_path, ec);
    if (g_signal_count.load() > 0) {
        std::fprintf(stderr, "whitted: interrupted: wrote %s before exiting\n", c.output.c_str());
        return 128 + g_last_signal.load();
    }
    const double write_s = seconds_since(t_write);

    std::fprintf(stderr,
                 "whitted: wrote %s (%dx%d)\n"
                 "  time   load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
                 "  rays   camera %llu  shadow %llu  reflection %llu  refraction %llu  total %llu\n"
                 "  skip   %s; shadow rays not cast: %llu unreached, %llu facing away, %llu with a zero term, "
                 "%llu too dim; "
                 "secondary rays below --min-weight %g: %llu\n"
                 "  speed  %.2f Mrays/s on %d threads\n"
                 "  aa     %s: %.3f camera rays/pixel, %.1f%% pixels subdivided\n",
                 c.output.c_str(), film.width(), film.height(), load_s, stats.build_seconds, stats.render_seconds,
                 write_s, (unsigned long long)stats.rays.camera, (unsigned long long)stats.rays.shadow,
                 (unsigned long long)stats.rays.reflection, (unsigned long long)stats.rays.refraction,
                 (unsigned long long)rays, kernel_name(renderer.kernel()).c_str(),
                 (unsigned long long)stats.rays.shadow_skipped_unreached,
                 (unsigned long long)stats.rays.shadow_skipped_facing,
                 (unsigned long long)stats.rays.shadow_skipped_zero,
                 (unsigned long long)stats.rays.shadow_skipped_dim, double(rs.integrator.min_weight),
                 (unsigned long long)stats.rays.secondary_skipped_cutoff, mrays, stats.threads, aa_name,
                 stats.pixels ? double(stats.rays.camera) / double(stats.pixels) : 0.0, 100.0 * subdivided);
    return 0;
}

int run_info(const std::string& input, const ImportOptions& io) {
    Scene scene = load_scene(input, io);
    std::fputs(describe_scene(scene).c_str(), stdout);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // Big buffers (images, environment maps, accelerators) fault in 2 MiB pages: on the machines
    // measured, page faults were half the time of a small run (docs/performance.md).
    restart_with_huge_pages(argv);
    // Under an MPI launcher (mpirun -n N whitted render ...): MPI for the process's life; a plain
    // run never initialises it (docs/distributed.md).
    std::optional<MpiSession> mpi;
    if (launched_by_mpi() && mpi_available()) {
        mpi.emplace();
        g_mpi = &*mpi;
    }
    CLI::App app{"whitted: a Whitted-style (1980) recursive ray tracer for glTF 2.0 scenes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("whitted ") + WHITTED_VERSION);
    std::string log_level = "info";
    app.add_option("--log-level", log_level, "Messages to print: debug, info, warning, error, off")
        ->check(CLI::IsMember({"debug", "info", "warning", "error", "off"}))
        ->capture_default_str();

    // whitted render: flags set the library's settings directly; colours, AOVs, the crop and the
    // anti-aliasing names are parsed straight into their types.
    RenderCommand rc;
    RenderSettings& rs = rc.render;
    CLI::App* render = app.add_subcommand("render", "Render a scene to an image");
    render->add_option("scene", rc.input, "Scene file (.gltf, .glb, or a .json scene file: docs/scene-format.md)")->required();
    render->add_option("-o,--output", rc.output,
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
    render->add_option("--scene", rc.import.scene_index, "glTF scene index (-1 = the file's default scene)")
        ->capture_default_str();
    render->add_option("--max-depth", rs.integrator.max_depth,
                       "Maximum depth of the ray tree (0 = no reflection/refraction)")
        ->check(CLI::Range(0, 64))->capture_default_str();
    render->add_option_function<std::string>(
              "--background", [&](const std::string& t) { rs.integrator.background = parse_color(t, "--background"); },
              "Radiance of rays that hit nothing: r,g,b or gray (linear)")
        ->default_str(color_text(rs.integrator.background));
    render->add_option_function<std::string>(
              "--ambient", [&](const std::string& t) { rs.integrator.ambient = parse_color(t, "--ambient"); },
              "Ambient light Ia: r,g,b or gray (linear)")
        ->default_str(color_text(rs.integrator.ambient));
    render->add_option_function<float>(
              "--exposure", [&](float stops) { rs.exposure = std::exp2(stops); },
              "Exposure in stops: radiance is scaled by 2^exposure")
        ->default_str("0");
    render->add_option("--min-weight", rs.integrator.min_weight,
                       "Adaptive tree depth (Hall & Greenberg 1983): skip reflected/refracted rays whose accumulated "
                       "weight is below this (default 1/255; 0 = trace to --max-depth)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    render->add_flag_function(
        "--no-specialize", [&](std::int64_t) { rs.integrator.specialize = false; },
        "Use the general shading kernel instead of the one the scene needs (to measure the gain)");
    render->add_flag("--fresnel", rs.integrator.fresnel,
                     "Weight reflection and transmission with Schlick's Fresnel term");
    render->add_flag("--refract-thin", rs.mapping.refract_thin,
                     "Refract through transmissive materials without KHR_materials_volume (classic glass)");
    render->add_option("--mirror-cutoff", rs.mapping.mirror_roughness_cutoff,
                       "Roughness at which mirror reflection has faded to 0 (see docs/materials.md)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    render->add_option_function<std::vector<std::string>>(
              "--aov", [&](const std::vector<std::string>& names) { rs.aovs = parse_aovs(names); },
              "Extra EXR channels: depth, normal, albedo, primid, instid, aa_samples, all")
        ->delimiter(',');
    render->add_option_function<std::string>(
              "--aa", [&](const std::string& name) { rs.aa.mode = parse_aa_mode(name); },
              "Anti-aliasing: center, corners, adaptive, stratified (docs/antialiasing.md)")
        ->check(CLI::IsMember({"center", "corners", "adaptive", "stratified"}))->default_str(aa_mode_name(rs.aa.mode));
    render->add_option("--aa-threshold", rs.aa.threshold,
                       "adaptive: split a square when its corners differ by more than this in display-referred "
                       "sRGB values (max channel difference); negative = always split")
        ->capture_default_str();
    render->add_option("--aa-depth", rs.aa.depth, "adaptive: maximum subdivision depth (sub-squares of 1/2^depth pixel)")
        ->check(CLI::Range(0, 8))->capture_default_str();
    render->add_option("--spp", rs.aa.spp, "stratified: samples per pixel, a square number k*k")
        ->check(CLI::Range(1, 4096))->capture_default_str();
    render->add_option_function<std::string>(
              "--filter", [&](const std::string& name) { rs.aa.filter = parse_pixel_filter(name); },
              "stratified: pixel filter, box or tent (radius 1 pixel)")
        ->check(CLI::IsMember({"box", "tent"}))->default_str(pixel_filter_name(rs.aa.filter));
    render->add_option_function<std::string>(
              "--texture-filter", [&](const std::string& name) { rs.aa.texture_filter = parse_texture_filter(name); },
              "Textures: mip (filtered over each sample's spacing: the pixel, pixel/k for stratified k*k, the "
              "sub-square for adaptive) or none (point samples of the finest level: Whitted's model exactly)")
        ->check(CLI::IsMember({"mip", "none"}))->default_str(texture_filter_name(rs.aa.texture_filter));
    render->add_option_function<std::string>(
        "--crop", [&](const std::string& t) { if (!t.empty()) rs.crop = parse_crop(t); },
        "Render only the region x0,y0,x1,y1 (pixels, x1/y1 exclusive)");
    render->add_option("--threads", rs.threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    render->add_option("--tile-size", rs.tile_size, "Tile size in pixels")->check(CLI::Range(1, 4096))
        ->capture_default_str();
    render->add_option("--accel", rs.accel,
                       "Acceleration structure: embree, bvh, grid, octree, kdop, brute; options after a colon, "
                       "e.g. bvh:precision=double,bv=sphere (docs/accelerators.md)")->capture_default_str();
    render->add_option("--precision", rc.precision,
                       "In-house BVH and brute force: trace in float or double (the reference), same as "
                       "--accel bvh:precision=...")->check(CLI::IsMember({"float", "double"}));
    render->add_option("--bv", rc.bv,
                       "In-house BVH bounding volume: aabb or sphere (Whitted's (1980) bounding spheres), same as "
                       "--accel bvh:bv=...")->check(CLI::IsMember({"aabb", "sphere"}));
    render->add_flag("--robust,!--no-robust", rs.robust,
                     "Embree robust mode (RTC_SCENE_FLAG_ROBUST, the default): no light leaks at shared edges; "
                     "--no-robust is 3-8% faster and leaks a few % of rays aimed at edges and vertices");
    add_output_options(render, rc.out);
    render->add_flag_function("--no-progress", [&](std::int64_t) { rs.progress = false; }, "Do not draw the progress bar");
    render->add_option("--max-memory", rc.max_memory_gb, "Refuse scenes whose data would exceed this many GiB")
        ->check(CLI::PositiveNumber)->capture_default_str();
    render->add_flag("--allow-outside-uris", rc.import.allow_outside_uris,
                     "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");
    add_environment_options(render, rc.import);
    render->add_option("--tile-job", rc.tile_job,
                       "Render only part i of n (i/n, 1 <= i <= n: horizontal bands) as an EXR part for `whitted "
                       "merge` (docs/distributed.md)");
    render->add_option("--checkpoint", rc.checkpoint_seconds,
                       "Save the finished tiles to the checkpoint at least every this many seconds (an interrupted "
                       "render always saves them)")->check(CLI::PositiveNumber);
    render->add_flag("--resume", rc.resume,
                     "Continue from the checkpoint: render only the tiles it lacks (refused when it was made with "
                     "other settings)");
    render->add_option("--tile-log", rc.tile_log,
                       "Write each tile's render time (and its message size to MPI rank 0) as CSV, for "
                       "scripts/simulate_mpi.py");
    render->add_option_function<std::string>(
              "--tile-order",
              [&rc](const std::string& v) {
                  rc.tile_order = v == "frame" ? TileOrder::Frame : v == "cost" ? TileOrder::ExpensiveFirst : TileOrder::Auto;
              },
              "Order the tiles are rendered in: cost (the dearest first, by a probe of 16 ray trees per tile, so "
              "that the last tiles are cheap), frame (row by row), or auto (cost from 8 worker threads over all "
              "processes on, else frame)")
        ->check(CLI::IsMember({"auto", "cost", "frame"}))
        ->default_str("auto");
    render->add_option("--checkpoint-file", rc.checkpoint_file,
                       "Checkpoint path (default: the output path + .checkpoint.exr)");

    // whitted info
    std::string info_input;
    ImportOptions info_import;
    CLI::App* info = app.add_subcommand("info", "Print what a scene file contains after import");
    info->add_option("scene", info_input, "Scene file (.gltf, .glb or .json)")->required();
    info->add_option("--scene", info_import.scene_index, "glTF scene index (-1 = the file's default scene)")
        ->capture_default_str();
    info->add_flag_function("--no-textures", [&](std::int64_t) { info_import.load_textures = false; },
                            "Skip decoding images");
    info->add_flag("--allow-outside-uris", info_import.allow_outside_uris,
                   "Let the file's external URIs leave its folder (../); absolute and file:// URIs stay refused");
    add_environment_options(info, info_import);

    // whitted merge
    std::vector<std::string> merge_parts_in;
    std::string merge_output;
    OutputSettings merge_out;
    CLI::App* merge = app.add_subcommand("merge", "Assemble the EXR parts of `render --tile-job i/n` into the frame");
    merge->add_option("parts", merge_parts_in, "The parts (EXR files written with --tile-job), in any order")->required();
    merge->add_option("-o,--output", merge_output,
                      "Output image; the extension picks the format, as for `render`")->required();
    add_output_options(merge, merge_out);

    // whitted bench <name>: benchmarks print figures and write CSV/plots (docs/performance.md).
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print figures, write CSV and plots");
    bench->require_subcommand(1);
    std::vector<app::Command> commands;
    // Each benchmark module registers itself here (one line each; benchmarks/bench_commands.h):
    commands.push_back(app::register_bench_aa(*bench));
    commands.push_back(app::register_bench_accel(*bench));
    commands.push_back(app::register_bench_env(*bench));
    commands.push_back(app::register_bench_process(*bench));
    commands.push_back(app::register_bench_scale(*bench));
    commands.push_back(app::register_bench_skip(*bench));
    commands.push_back(app::register_bench_stability(*bench));

    // Global options (--log-level) may also follow the subcommand.
    render->fallthrough();
    info->fallthrough();
    merge->fallthrough();
    bench->fallthrough();
    for (app::Command& c : commands) c.app->fallthrough();

    // Flags parsed into their types (colours, crop, AOVs) throw whitted::Error while CLI11 parses:
    // reported like every other Error, in one line with exit code 1.
    try {
        app.parse(argc, argv);
    } catch (const Error& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
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
        log_debug("malloc: transparent huge pages {}", huge_pages_requested() ? "requested (GLIBC_TUNABLES)" : "not requested");
        // Under MPI only rank 0 reports; the others print errors only (each rank loads the same scene).
        if (g_mpi && g_mpi->rank() > 0) set_log_level(std::max(parse_log_level(log_level), LogLevel::Error));
        if (render->parsed()) {
            // A setting's scene-file key names its flag: aa_threshold -> --aa-threshold.
            const SettingGiven flag_given = [&](std::string_view key) { return render->count(setting_flag(key)) > 0; };
            return run_render(rc, command_line(argc, argv), flag_given, g_mpi);
        }
        if (info->parsed()) return run_info(info_input, info_import);
        if (merge->parsed()) return run_merge(merge_parts_in, merge_output, merge_out, command_line(argc, argv));
        for (app::Command& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const MpiSetupFailed& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 1;
    } catch (const Error& e) {
        if (g_mpi && g_mpi_running.load()) {
            std::fprintf(stderr, "whitted: error: rank %d: %s\n", g_mpi->rank(), e.what());
            g_mpi->abort(1);
        }
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
