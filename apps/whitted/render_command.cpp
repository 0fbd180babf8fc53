// `whitted render`: load, configure, render the frame, write, summarise (docs/cli.md).
#include "render_command.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "accel/factory/create_accelerator.h"
#include "core/error.h"
#include "core/log.h"
#include "importers/scene_report.h"
#include "integrator/render.h"
#include "interrupt.h"
#include "session/mpi_frame.h"
#include "session/sequence.h"
#include "session/tile_job.h"

namespace whitted::cli {

namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

const Clock::time_point g_process_start = Clock::now();

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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

/// A render set up: the scene, what the pixels depend on, the renderer.
struct Prepared {
    Scene scene;
    std::unique_ptr<SceneAnimator> animator;  ///< a sequence's: poses the scene at each frame's time
    double load_seconds = 0.0;
    SettingList identity;  ///< recorded by checkpoints and tile-job parts, checked by --resume and merge
    std::unique_ptr<Renderer> renderer;
};

/// --tile-job i/n: the band to render becomes the crop; the part records its job and frame, in float.
void apply_tile_job(RenderCommand& c, const Scene& scene, const SettingList& identity) {
    RenderSettings& rs = c.render;
    const TileJob job = parse_tile_job(c.tile_job);
    if (fs::path(c.output).extension() != ".exr")
        throw Error(fmt::format("--tile-job writes an EXR part (merge it with `whitted merge`): got -o {}", c.output));
    if (rs.camera < 0 || size_t(rs.camera) >= scene.cameras.size())
        throw Error(fmt::format("--camera {}: the scene has {} camera(s)", rs.camera, scene.cameras.size()));
    const ImageSize full = resolve_image_size(scene.cameras[size_t(rs.camera)], rs.width, rs.height);
    const PixelWindow frame = rs.crop.value_or(PixelWindow{0, 0, full.width, full.height});
    rs.crop = tile_job_window(frame, job);
    for (const auto& [key, value] : tile_job_metadata(job, frame, identity)) c.out.metadata[key] = value;
    c.out.exr_half = false;  // exact: the merged frame is bit-identical to a one-piece render
}

/// Loads the scene (with `animated`, keeping its animator), lets its settings fill what the flags
/// did not set, checks the colour pipeline, lets `adjust` change the scene (a sequence's camera)
/// and builds the renderer.
void prepare(RenderCommand& c, const SettingGiven& given, Prepared& p,
             const std::function<void(Prepared&, const RenderSettings&)>& adjust = {}, bool animated = false) {
    RenderSettings& rs = c.render;
    const auto t_load = Clock::now();
    c.import.max_memory = size_t(c.max_memory_gb * double(size_t(1) << 30));
    set_accelerator_memory_limit(c.import.max_memory);
    if (animated) {
        AnimatedScene a = load_animated_scene(c.input, c.import);
        p.scene = std::move(a.scene);
        p.animator = std::move(a.animator);
    } else {
        p.scene = load_scene(c.input, c.import);
    }
    p.load_seconds = seconds_since(t_load);
    for (const std::string& w : p.scene.warnings) log_warning("{}: {}", c.input, w);

    apply_scene_settings(p.scene.settings, rs, given);
    apply_scene_output_settings(p.scene.settings, c.input, c.output, c.out, given);
    if (!(rs.integrator.min_weight >= 0.f && rs.integrator.min_weight <= 1.f))
        throw Error(fmt::format("min_weight {} is out of range (expected 0 to 1)", rs.integrator.min_weight));
    rs.accel = with_spec_options(rs.accel, {{"precision", c.precision}, {"bv", c.bv}});
    { DisplayTransform check(c.out.color); }  // bad colour flags fail before the (long) render

    p.identity = {{"version", WHITTED_VERSION}, {"scene", c.input + " (" + file_identity(c.input) + ")"}};
    for (auto& kv : describe_import_options(c.import)) p.identity.push_back(kv);
    for (auto& kv : describe_image_settings(rs)) p.identity.push_back(kv);
    if (!c.tile_job.empty()) apply_tile_job(c, p.scene, p.identity);
    if (adjust) adjust(p, rs);
    p.renderer = std::make_unique<Renderer>(p.scene, rs);
}

/// What the scene uses and what the renderer skips (docs/performance.md), in the log.
void log_scene(const RenderCommand& c, const Scene& scene, const Renderer& renderer) {
    const ImageSize size = renderer.image_size();
    const int camera = c.render.camera;
    log_info("{}: {} triangles in {} instances, {} lights, camera {}/{}{}, {}x{}", c.input,
             scene.instanced_triangle_count(), scene.instances.size(), scene.lights.size(), camera,
             scene.cameras.size(), scene.cameras[size_t(camera)].is_default ? " (default)" : "", size.width,
             size.height);
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

FrameOptions frame_options(const RenderCommand& c, const SettingList& identity, const Renderer& renderer) {
    FrameOptions fo;
    fo.identity = identity;
    const PixelWindow w = renderer.window();
    fo.identity.emplace_back("window", fmt::format("{},{},{},{}", w.x0, w.y0, w.x1, w.y1));
    fo.checkpoint_path = c.checkpoint_file.empty() ? checkpoint_path_for(c.output) : c.checkpoint_file;
    fo.checkpoint_seconds = c.checkpoint_seconds;
    fo.resume = c.resume;
    fo.stop = &interrupts().stop;
    fo.progress = c.render.progress;
    fo.order = c.tile_order;
    return fo;
}

/// The frame's tiles rendered here and, under MPI, by the other ranks too.
FrameResult render_tiles(const RenderCommand& c, const FrameOptions& fo, const Renderer& renderer, MpiSession* mpi) {
    InterruptState& signals = interrupts();
    signals.rendering.store(true);
    std::optional<MpiTileServer> server;
    if (mpi && mpi->size() > 1) {
        server.emplace(*mpi, renderer);
        signals.mpi_running.store(true);
        log_info("MPI: {} ranks, {} threads each", mpi->size(), renderer.settings().threads);
    }
    const double startup = seconds_since(g_process_start);
    FrameResult frame = render_frame(renderer, fo, server ? &*server : nullptr);
    signals.mpi_running.store(false);
    if (mpi) mpi->finish();  // every tile is in: the other ranks exit while this one writes
    signals.rendering.store(false);
    if (!c.tile_log.empty())
        write_tile_log(c.tile_log, frame, fs::path(c.input).filename().string(), c.render.tile_size,
                       frame.stats.threads, startup);
    return frame;
}

/// The rates a render's summary and metadata report.
struct Rates {
    double mrays = 0.0;       ///< million rays per second of the render phase
    double per_pixel = 0.0;   ///< camera rays per pixel
    double subdivided = 0.0;  ///< fraction of the pixels the adaptive mode split
};

Rates rates_of(const RenderStats& s) {
    Rates r;
    r.mrays = s.render_seconds > 0 ? double(s.rays.total()) / s.render_seconds * 1e-6 : 0.0;
    r.per_pixel = s.pixels ? double(s.rays.camera) / double(s.pixels) : 0.0;
    r.subdivided = s.pixels ? double(s.pixels_subdivided) / double(s.pixels) : 0.0;
    return r;
}

/// One line of the whole run for the image's metadata.
std::string stats_line(const Prepared& p, const RenderStats& stats, AaMode aa) {
    const Rates r = rates_of(stats);
    return fmt::format(
        "time: load {:.3f}s, build {:.3f}s, render {:.3f}s | rays: {} camera, {} shadow, {} reflection, "
        "{} refraction, {} aov probe, {} total, {:.2f} Mrays/s on {} threads | aa: {} ({:.3f} camera rays/pixel, "
        "{:.1f}% pixels subdivided)",
        p.load_seconds, stats.build_seconds, stats.render_seconds, stats.rays.camera, stats.rays.shadow,
        stats.rays.reflection, stats.rays.refraction, stats.rays.aov_probe, stats.rays.total(), r.mrays,
        stats.threads, aa_mode_name(aa), r.per_pixel, 100.0 * r.subdivided);
}

/// The summary on stderr after a finished frame: time split, rays by kind, what was skipped, speed.
void print_summary(const RenderCommand& c, const Prepared& p, const FrameResult& frame, double write_seconds) {
    const RenderStats& s = frame.stats;
    const auto n = [](uint64_t v) { return (unsigned long long)v; };
    const Rates r = rates_of(s);
    std::fprintf(stderr,
                 "whitted: wrote %s (%dx%d)\n"
                 "  time   load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
                 "  rays   camera %llu  shadow %llu  reflection %llu  refraction %llu  occlusion %llu  total %llu\n"
                 "  skip   %s; shadow rays not cast: %llu unreached, %llu facing away, %llu with a zero term, "
                 "%llu too dim; occlusion rays too dim: %llu; secondary rays below --min-weight %g: %llu\n"
                 "  speed  %.2f Mrays/s on %d threads\n"
                 "  aa     %s: %.3f camera rays/pixel, %.1f%% pixels subdivided\n",
                 c.output.c_str(), frame.film.width(), frame.film.height(), p.load_seconds, s.build_seconds,
                 s.render_seconds, write_seconds, n(s.rays.camera), n(s.rays.shadow), n(s.rays.reflection),
                 n(s.rays.refraction), n(s.rays.occlusion), n(s.rays.total()), kernel_name(p.renderer->kernel()).c_str(),
                 n(s.rays.shadow_skipped_unreached), n(s.rays.shadow_skipped_facing), n(s.rays.shadow_skipped_zero),
                 n(s.rays.shadow_skipped_dim), n(s.rays.occlusion_skipped_dim), double(c.render.integrator.min_weight),
                 n(s.rays.secondary_skipped_cutoff), r.mrays, s.threads, aa_mode_name(c.render.aa.mode), r.per_pixel,
                 100.0 * r.subdivided);
}

/// Writes the frame (a partial one with its missing tiles listed) and returns the exit code: 0, or
/// 128 + signal after an interrupt.
int write_frame(RenderCommand& c, const Prepared& p, const FrameResult& frame, const FrameOptions& fo,
                const std::string& cmdline) {
    InterruptState& signals = interrupts();
    const std::vector<size_t> missing = frame.missing();
    if (!missing.empty()) {
        c.out.metadata["whitted:missingTiles"] = describe_tiles(frame.tiles, missing);
        c.out.metadata["whitted:incomplete"] = fmt::format(
            "{} of {} tiles missing (0 in the image); continue with --resume", missing.size(), frame.tiles.size());
    }
    const auto t_write = Clock::now();
    c.out.metadata["whitted:commandLine"] = cmdline;
    c.out.metadata["whitted:version"] = WHITTED_VERSION;
    c.out.metadata["whitted:stats"] = stats_line(p, frame.stats, c.render.aa.mode);
    c.out.metadata["Software"] = std::string("whitted ") + WHITTED_VERSION;
    signals.writing.store(true);
    write_image(frame.film, c.output, c.out);
    signals.writing.store(false);
    if (!missing.empty()) {
        const std::string resume = fo.checkpoint_path.empty()
                                       ? std::string(" (a sequence keeps no checkpoint)")
                                       : " and the checkpoint " + fo.checkpoint_path + "; continue with --resume";
        std::fprintf(stderr,
                     "whitted: interrupted: wrote %s with %zu of %zu tiles (the missing ones are 0 and listed in its "
                     "metadata)%s\n",
                     c.output.c_str(), frame.tiles.size() - missing.size(), frame.tiles.size(), resume.c_str());
        return 128 + signals.last_signal.load();
    }
    std::error_code ec;
    fs::remove(fo.checkpoint_path, ec);  // the finished frame is written: its checkpoint is not needed
    if (signals.signals.load() > 0) {
        std::fprintf(stderr, "whitted: interrupted: wrote %s before exiting\n", c.output.c_str());
        return 128 + signals.last_signal.load();
    }
    print_summary(c, p, frame, seconds_since(t_write));
    return 0;
}

/// The bounds of every frame of a sequence, when its camera is the default one (which then frames
/// them all and stays fixed), else nothing: the scene posed at each frame, then at the first again.
std::optional<Bounds3d> sequence_bounds(Prepared& p, const RenderSettings& rs, const FrameRange& range) {
    if (rs.camera < 0 || size_t(rs.camera) >= p.scene.cameras.size() || !p.scene.cameras[size_t(rs.camera)].is_default)
        return std::nullopt;
    return whitted::sequence_bounds(p.scene, *p.animator, range);
}

/// `render --frames A-B`: the scene loaded once and posed at each frame's time k / fps (only what
/// moves is updated: Renderer::update), every frame rendered and written like a single image.
int run_sequence(const RenderCommand& c0, const std::string& cmdline, const SettingGiven& given, MpiSession* mpi) {
    FrameRange range = parse_frame_range(c0.frames);
    range.fps = c0.fps;
    (void)frame_path(c0.output, range.first);  // an output name without '#' fails before anything is done
    if (mpi && mpi->size() > 1)
        throw Error("--frames under mpirun is not supported yet: render the frames as separate runs");
    if (!c0.tile_job.empty() || c0.resume || c0.checkpoint_seconds > 0)
        throw Error("--frames: --tile-job, --checkpoint and --resume apply to one image, not to a sequence");
    install_interrupt_handlers();
    std::optional<Bounds3d> bounds;
    // The default camera of frame k: framing every frame's bounds, turned by its share of --orbit.
    const auto place_camera = [&](Prepared& p, const RenderSettings& rs, int k) {
        if (!bounds) return false;
        p.scene.cameras[size_t(rs.camera)] = default_camera(*bounds, c0.orbit * double(k - range.first) / double(range.count()));
        return true;
    };
    RenderCommand c = c0;
    c.import.time = frame_time(range.first, range.fps);
    Prepared p;
    prepare(c, given, p, [&](Prepared& prepared, const RenderSettings& rs) {
        bounds = sequence_bounds(prepared, rs, range);
        place_camera(prepared, rs, range.first);
    }, true);
    if (c0.orbit != 0.0 && !bounds) log_warning("--orbit turns the default camera only: the file's camera is used");
    log_scene(c, p.scene, *p.renderer);
    for (int k = range.first; k <= range.last; ++k) {
        if (interrupts().signals.load() > 0) return 128 + interrupts().last_signal.load();
        c.import.time = frame_time(k, range.fps);
        c.output = frame_path(c0.output, k);
        if (k > range.first) {
            const size_t warned = p.scene.warnings.size();
            const auto t_pose = Clock::now();
            SceneUpdate u = p.animator->pose(p.scene, c.import.time);
            p.load_seconds = seconds_since(t_pose);
            u.cameras |= place_camera(p, c.render, k);
            if (u.reloaded) {
                p.renderer = std::make_unique<Renderer>(p.scene, c.render);
            } else {
                const Renderer::Update done = p.renderer->update(u);
                log_debug("frame {}: {} meshes and {} instances moved, accelerator {} in {:.3f}s", k, u.meshes.size(),
                          u.instances.size(), done.refit ? "refit" : "rebuilt", done.seconds);
            }
            for (size_t w = u.reloaded ? 0 : warned; w < p.scene.warnings.size(); ++w)
                log_warning("{}: {}", c.input, p.scene.warnings[w]);
        }
        FrameOptions fo = frame_options(c, p.identity, *p.renderer);
        fo.checkpoint_path.clear();  // a sequence keeps no checkpoint
        const FrameResult frame = render_tiles(c, fo, *p.renderer, nullptr);
        if (const int code = write_frame(c, p, frame, fo, cmdline); code != 0) return code;
    }
    std::fprintf(stderr, "whitted: wrote %d frames, %s to %s\n", range.count(), frame_path(c0.output, range.first).c_str(),
                 frame_path(c0.output, range.last).c_str());
    return 0;
}

}  // namespace

int run_render(RenderCommand c, const std::string& cmdline, const SettingGiven& given, MpiSession* mpi) {
    if (!c.frames.empty()) return run_sequence(c, cmdline, given, mpi);
    const bool root = !mpi || mpi->rank() == 0;
    if (root) install_interrupt_handlers();
    else ignore_interrupts();  // mpirun passes signals on to every rank: rank 0 decides
    Prepared p;
    std::string setup_error;
    try {
        prepare(c, given, p);
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
    if (mpi && mpi->size() > 1 && !root) {  // a worker rank: tiles for rank 0, nothing else
        interrupts().mpi_running.store(true);
        serve_mpi_worker(*mpi, *p.renderer);
        return 0;
    }
    log_scene(c, p.scene, *p.renderer);
    const FrameOptions fo = frame_options(c, p.identity, *p.renderer);
    const FrameResult frame = render_tiles(c, fo, *p.renderer, mpi);
    return write_frame(c, p, frame, fo, cmdline);
}

}  // namespace whitted::cli
