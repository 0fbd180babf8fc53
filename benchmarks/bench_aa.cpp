// `whitted bench aa SCENE...`: run time against error for every anti-aliasing mode.
//
// For each scene: a converged box-filtered reference (stratified, --ref-spp samples per pixel,
// cached on disk by a hash of the scene files and the settings), then every mode over a sweep of
// settings on the same accelerator. Each run reports its time (process CPU time by default, or
// wall time; the minimum of --repeat runs, interleaved over the sweep so a burst of load on a
// shared machine does not hit one setting only), primary, total and per-kind ray counts, RMSE /
// PSNR / relative MSE against the reference in linear and in display-referred values (the OCIO
// "Standard" view, clamped to [0, 1]) and the fraction of pixels adaptive sampling subdivided.
// It prints the targets (adaptive against stratified 16 spp, corners against center) with the
// decomposition of adaptive's cost (camera rays, rays per camera ray, time per ray) and, with
// --replay, how much of each target run is outside the ray trees. For the adaptive target it also
// bisects the threshold between the sweep's octave steps (--target-search; those runs go to
// <out>/aa_target_search.csv). Writes <out>/aa.csv, per scene
// the reference image and an adaptive sample-density heat map, and (when python3 with matplotlib
// is available) the error-against-time plots through scripts/plot_aa.py. See docs/antialiasing.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/ray_recording.h"
#include "importers/scene_loader.h"
#include "core/error.h"
#include "core/log.h"
#include "integrator/camera.h"
#include "integrator/render.h"
#include "output/image_output.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;

/// Bumped whenever a renderer change invalidates cached references.
constexpr const char* kReferenceVersion = "aa-reference-v4";  // v2: ray offsets in units of the hit primitive; v3: opaque covers (default.glb); v4: texture footprint = sample spacing

struct BenchAaOptions {
    std::vector<std::string> scenes;
    int width = 160;                 ///< image width in pixels (height from the camera aspect)
    int ref_spp = 256;               ///< reference samples per pixel (k*k, box filter)
    int repeat = 3;                  ///< timed runs per setting (fewer once a setting has taken 2 s); the minimum is reported
    int threads = 0;                 ///< 0 = all cores
    int max_depth = -1;              ///< ray-tree depth; -1 = the scene file's, else 5
    std::string timing = "cpu";      ///< "cpu": process CPU time (robust on a shared machine; use --threads 1), "wall"
    std::string out = "bench-aa";    ///< output directory (CSV, images, plots)
    std::string cache;               ///< reference cache directory; empty = $XDG_CACHE_HOME/whitted or ~/.cache/whitted
    bool quick = false;              ///< a shorter sweep
    std::vector<std::string> only;   ///< when given: run only the settings with these labels (as printed; adaptive ones may lie outside the sweep)
    bool replay = false;             ///< split the target runs' CPU time into ray trees and the rest (needs --threads 1)
    int target_search = 3;           ///< bisection steps of the threshold search at the target (0 = the sweep's settings only)
    bool plot = true;                ///< run scripts/plot_aa.py afterwards when possible
    std::string python = default_python();  ///< interpreter with matplotlib for the plots
};

/// One benchmark run: the settings and what they measured.
struct Run {
    std::string scene;
    AaSettings aa;
    double seconds = 0.0;            ///< the reported time: cpu_seconds or wall_seconds (--timing)
    double cpu_seconds = 1e30;       ///< minimum process CPU time of one render
    double wall_seconds = 1e30;      ///< minimum wall time of one render
    double spent = 0.0;              ///< time spent on this setting so far (for the 2 s budget)
    Film film;                       ///< the last image (every run gives the same one)
    RenderStats stats;
    double rmse_lin = 0, psnr_lin = 0, relmse_lin = 0, rmse_disp = 0, psnr_disp = 0, relmse_disp = 0;
    bool pareto = false;
};

/// FNV-1a 64 over bytes.
uint64_t fnv1a(uint64_t h, const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

/// Hash of the scene's files: a .glb alone; a .gltf with every file of its directory (buffers and
/// images live next to it), in sorted order so the hash does not depend on directory order.
uint64_t hash_scene_files(const fs::path& scene) {
    std::vector<fs::path> files{scene};
    if (scene.extension() != ".glb") {
        files.clear();
        for (const auto& e : fs::directory_iterator(scene.parent_path().empty() ? fs::path(".") : scene.parent_path()))
            if (e.is_regular_file()) files.push_back(e.path());
        std::sort(files.begin(), files.end());
    }
    uint64_t h = 0xcbf29ce484222325ull;
    for (const fs::path& f : files) {
        std::ifstream in(f, std::ios::binary);
        std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::string name = f.filename().string();
        h = fnv1a(h, name.data(), name.size());
        h = fnv1a(h, bytes.data(), bytes.size());
    }
    return h;
}

fs::path default_cache_dir() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && xdg[0]) return fs::path(xdg) / "whitted";
    if (const char* home = std::getenv("HOME"); home && home[0]) return fs::path(home) / ".cache" / "whitted";
    return fs::temp_directory_path() / "whitted-cache";
}

std::string scene_label(const fs::path& p) { return p.stem().string(); }

/// Error metrics of `img` against `ref` (packed RGB): RMSE, PSNR (peak 1) and relative MSE
/// (mean of (a - b)^2 / (b^2 + 0.01), per channel).
void metrics(const std::vector<float>& img, const std::vector<float>& ref, double& rmse, double& psnr, double& relmse) {
    double se = 0.0, rel = 0.0;
    for (size_t i = 0; i < ref.size(); ++i) {
        const double d = double(img[i]) - double(ref[i]);
        se += d * d;
        rel += d * d / (double(ref[i]) * double(ref[i]) + 0.01);
    }
    const double mse = se / double(ref.size());
    rmse = std::sqrt(mse);
    psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : 999.0;
    relmse = rel / double(ref.size());
}

std::vector<float> packed(const Film& film) {
    std::vector<float> rgb(film.beauty.size() * 3);
    for (size_t i = 0; i < film.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = film.beauty[i][c];
    return rgb;
}

/// Display-referred values: the OCIO transform, NaN -> 0, clamped to [0, 1] (what a PNG stores).
std::vector<float> to_display(std::vector<float> rgb, const DisplayTransform& display) {
    display.apply(rgb.data(), rgb.size() / 3);
    for (float& v : rgb) v = std::isnan(v) ? 0.f : std::clamp(v, 0.f, 1.f);
    return rgb;
}

/// A perceptually ordered colour map (viridis, 9 control points, linearly interpolated), display values.
Color viridis(float t) {
    static const float k[9][3] = {{0.267f, 0.005f, 0.329f}, {0.282f, 0.141f, 0.458f}, {0.254f, 0.265f, 0.530f},
                                  {0.207f, 0.372f, 0.553f}, {0.164f, 0.471f, 0.558f}, {0.128f, 0.567f, 0.551f},
                                  {0.135f, 0.659f, 0.518f}, {0.478f, 0.821f, 0.318f}, {0.993f, 0.906f, 0.144f}};
    t = std::clamp(t, 0.f, 1.f) * 8.f;
    const int i = std::min(int(t), 7);
    const float f = t - float(i);
    return {k[i][0] + (k[i + 1][0] - k[i][0]) * f, k[i][1] + (k[i + 1][1] - k[i][1]) * f,
            k[i][2] + (k[i + 1][2] - k[i][2]) * f};
}

/// Writes the aa_samples AOV as a heat map PNG (log scale from 4 to (2^depth + 1)^2 samples).
void write_heat_map(const Film& film, int depth, const fs::path& path) {
    Film heat(film.full_width, film.full_height, film.window, AovSet{});
    const double lo = std::log(4.0), hi = std::log(std::pow(double((1 << depth) + 1), 2.0));
    for (size_t i = 0; i < film.aa_samples.size(); ++i) {
        const double s = std::max(1.0, double(film.aa_samples[i]));
        heat.beauty[i] = viridis(float((std::log(s) - lo) / (hi - lo)));
    }
    OutputSettings os;
    os.color.view = "Raw";  // the colour map is already display-referred
    write_image(heat, path.string(), os);
}

std::string describe(const AaSettings& aa) {
    switch (aa.mode) {
        case AaMode::Center:
        case AaMode::Corners: return aa_mode_name(aa.mode);
        case AaMode::Adaptive: return fmt::format("adaptive t={:g} d={}", aa.threshold, aa.depth);
        case AaMode::Stratified: return fmt::format("stratified {} spp {}", aa.spp, pixel_filter_name(aa.filter));
    }
    return "?";
}

/// The settings swept for every scene.
std::vector<AaSettings> sweep(bool quick) {
    std::vector<AaSettings> s;
    auto add = [&](AaMode mode, float threshold, int depth, int spp, PixelFilter filter) {
        AaSettings a;
        a.mode = mode;
        a.threshold = threshold;
        a.depth = depth;
        a.spp = spp;
        a.filter = filter;
        s.push_back(a);
    };
    add(AaMode::Center, 0, 0, 1, PixelFilter::Box);
    add(AaMode::Corners, 0, 0, 1, PixelFilter::Box);
    const std::vector<int> depths = quick ? std::vector<int>{3} : std::vector<int>{1, 2, 3};
    const std::vector<float> thresholds =
        quick ? std::vector<float>{0.2f, 0.1f, 0.05f} : std::vector<float>{0.4f, 0.2f, 0.1f, 0.05f, 0.025f, 0.0125f};
    for (int d : depths)
        for (float t : thresholds) add(AaMode::Adaptive, t, d, 1, PixelFilter::Box);
    const std::vector<int> spps = quick ? std::vector<int>{4, 16, 64} : std::vector<int>{1, 4, 9, 16, 36, 64};
    for (int n : spps) add(AaMode::Stratified, 0, 0, n, PixelFilter::Box);
    for (int n : quick ? std::vector<int>{16} : std::vector<int>{4, 16, 64}) add(AaMode::Stratified, 0, 0, n, PixelFilter::Tent);
    return s;
}

/// The settings to run: the sweep, or with --only the labelled ones. An adaptive label outside the
/// sweep ('adaptive t=0.0595 d=2', as the threshold search prints them) adds that setting, so a
/// searched setting can be timed again; any other unknown label is an error (a misspelt one would
/// silently run nothing).
std::vector<AaSettings> selected_settings(bool quick, const std::vector<std::string>& only) {
    const std::vector<AaSettings> all = sweep(quick);
    if (only.empty()) return all;
    std::vector<AaSettings> out;
    for (const AaSettings& aa : all)
        if (std::find(only.begin(), only.end(), describe(aa)) != only.end()) out.push_back(aa);
    for (const std::string& label : only) {
        if (std::any_of(all.begin(), all.end(), [&](const AaSettings& aa) { return describe(aa) == label; })) continue;
        AaSettings aa;
        aa.mode = AaMode::Adaptive;
        char tail = 0;
        const bool parsed = std::sscanf(label.c_str(), "adaptive t=%f d=%d%c", &aa.threshold, &aa.depth, &tail) == 2;
        if (!parsed || aa.depth < 0 || aa.depth > 8 || describe(aa) != label)
            throw Error(fmt::format("--only '{}': no such setting in the sweep, nor an adaptive setting 'adaptive t=T d=D' "
                                    "with D in 0..8 (labels as printed, e.g. 'adaptive t=0.05 d=2', 'stratified 16 spp box')",
                                    label));
        if (std::none_of(out.begin(), out.end(), [&](const AaSettings& o) { return describe(o) == label; })) out.push_back(aa);
    }
    return out;
}

/// Where a render's CPU time goes: the time of the render (min of `repeat`) and of tracing the same
/// camera rays, recorded from it, through the integrator in a plain loop on this thread (the ray
/// trees alone). The difference is what the sampling mode adds: camera ray generation, the AA
/// logic (subdivision, shared points), the film.
struct ReplaySplit {
    double render_seconds = 1e30, replay_seconds = 1e30;
};

ReplaySplit replay_split(const Renderer& renderer, const Scene& scene, const RenderSettings& rs, const AaSettings& aa,
                         int repeat) {
    const RecordingAccelerator recorder(renderer.accelerator());
    (void)renderer.render(aa, rs.integrator, recorder);
    std::vector<Ray> camera_rays;
    for (const RecordedRay& r : recorder.rays())
        if (r.kind == RayKind::Camera && !r.shadow) camera_rays.push_back(r.ray);
    const ImageSize size = renderer.image_size();
    const RayCone cone = CameraModel(scene.cameras[size_t(rs.camera)], size.width, size.height).pixel_cone();
    const WhittedIntegrator integrator(renderer.view(), renderer.accelerator(), rs.integrator);
    ReplaySplit split;
    for (int i = 0; i < std::max(1, repeat); ++i) {  // interleaved, minimum of each
        double t0 = process_cpu_seconds();
        (void)renderer.render(aa);
        split.render_seconds = std::min(split.render_seconds, process_cpu_seconds() - t0);
        RayCounters rc;
        Color sum(0.f);
        t0 = process_cpu_seconds();
        for (const Ray& ray : camera_rays) sum += integrator.trace(ray, RayKind::Camera, 0, rc, nullptr, cone);
        split.replay_seconds = std::min(split.replay_seconds, process_cpu_seconds() - t0);
        if (!is_finite(sum)) log_debug("bench aa: replay summed to a non-finite value");  // keeps the loop alive
    }
    return split;
}

/// The target's threshold search (`--target-search`): for each adaptive depth of the sweep, the
/// largest threshold whose display RMSE is at most `target` and the next larger threshold of that
/// depth, which misses it, are bisected `steps` times at their geometric mean; `render(t, d)`
/// measures one setting. Returns the runs it measured, in order. A depth is skipped when none of
/// its thresholds reaches the target or when its largest one already does (nothing to narrow).
template <typename RenderFn>
std::vector<Run> threshold_search(const std::vector<Run>& sweep_runs, double target, int steps, RenderFn&& render) {
    std::vector<Run> out;
    if (steps <= 0) return out;
    std::vector<int> depths;
    for (const Run& r : sweep_runs)
        if (r.aa.mode == AaMode::Adaptive && std::find(depths.begin(), depths.end(), r.aa.depth) == depths.end())
            depths.push_back(r.aa.depth);
    for (const int d : depths) {
        float pass = 0.f, fail = 0.f;  // thresholds; 0 = none
        for (const Run& r : sweep_runs)
            if (r.aa.mode == AaMode::Adaptive && r.aa.depth == d && r.rmse_disp <= target) pass = std::max(pass, r.aa.threshold);
        if (!(pass > 0.f)) continue;
        for (const Run& r : sweep_runs)
            if (r.aa.mode == AaMode::Adaptive && r.aa.depth == d && r.aa.threshold > pass && r.rmse_disp > target &&
                (fail == 0.f || r.aa.threshold < fail))
                fail = r.aa.threshold;
        if (!(fail > 0.f)) continue;
        for (int k = 0; k < steps; ++k) {
            // Three significant digits keep the labels readable; stop once they cannot split further.
            const float t = std::stof(fmt::format("{:.3g}", std::sqrt(double(pass) * double(fail))));
            if (!(t > pass && t < fail)) break;
            out.push_back(render(t, d));
            (out.back().rmse_disp <= target ? pass : fail) = t;
        }
    }
    return out;
}

/// Marks the runs no other run beats in both time and display RMSE.
void mark_pareto(std::vector<Run>& runs) {
    for (Run& r : runs) {
        r.pareto = std::none_of(runs.begin(), runs.end(), [&](const Run& o) {
            return &o != &r && o.seconds <= r.seconds && o.rmse_disp <= r.rmse_disp &&
                   (o.seconds < r.seconds || o.rmse_disp < r.rmse_disp);
        });
    }
}

int run_bench_aa(const BenchAaOptions& o) {
    if (o.scenes.empty()) throw Error("bench aa: give at least one scene");
    if (stratified_side(o.ref_spp) == 0) throw Error(fmt::format("--ref-spp must be a square number (got {})", o.ref_spp));
    const fs::path out(o.out);
    fs::create_directories(out);
    const fs::path cache = (o.cache.empty() ? default_cache_dir() : fs::path(o.cache)) / "aa-references";
    fs::create_directories(cache);
    if (o.timing != "cpu" && o.timing != "wall") throw Error(fmt::format("--timing: expected cpu or wall, got '{}'", o.timing));
    const bool cpu_time = o.timing == "cpu";
    const std::vector<AaSettings> settings = selected_settings(o.quick, o.only);
    if (o.replay && o.threads != 1) throw Error("bench aa: --replay compares process CPU times and needs --threads 1");
    const DisplayTransform display(ColorSettings{});

    const std::string csv_header =
        "scene,mode,filter,threshold,depth,spp,label,seconds,camera_rays,total_rays,camera_rays_per_pixel,"
           "rmse_linear,psnr_linear,relmse_linear,rmse_display,psnr_display,relmse_display,subdivided_fraction,"
           "pareto,timing,cpu_seconds,wall_seconds,shadow_rays,secondary_rays,threads,load\n";
    std::ofstream csv(out / "aa.csv");
    csv << csv_header;
    // The threshold search's runs (the target), apart from the sweep the plots show.
    std::ofstream search_csv(out / "aa_target_search.csv");
    search_csv << csv_header;

    for (const std::string& scene_path : o.scenes) {
        const std::string label = scene_label(scene_path);
        Scene scene = load_scene(scene_path);
        // A scene file's settings (ambient, background, ray depth, ...) apply; size and AA are the bench's.
        RenderSettings rs;
        apply_scene_settings(scene.settings, rs);
        rs.width = o.width;
        rs.height = 0;
        rs.threads = o.threads;
        rs.progress = false;
        rs.aa = AaSettings{};
        if (o.max_depth >= 0) rs.integrator.max_depth = o.max_depth;
        else if (!scene.settings.max_depth) rs.integrator.max_depth = 5;
        Renderer renderer(scene, rs);
        const ImageSize size = renderer.image_size();
        std::printf("== %s: %dx%d, %zu triangles, build %.3fs, ray depth %d, %s time, load %.2f\n", label.c_str(),
                    size.width, size.height, scene.instanced_triangle_count(), renderer.build_seconds(),
                    rs.integrator.max_depth, cpu_time ? "process CPU" : "wall", load_average_1min());

        // Reference: cached by scene files + settings (+ renderer version tag).
        const std::string key_text = fmt::format("{}|{}|{}x{}|spp={}|box|depth={}|{}", kReferenceVersion, WHITTED_VERSION,
                                                 size.width, size.height, o.ref_spp, rs.integrator.max_depth, label);
        const uint64_t key = fnv1a(hash_scene_files(scene_path), key_text.data(), key_text.size());
        const fs::path ref_path = cache / fmt::format("{}-{:016x}.exr", label, key);
        std::vector<float> ref;
        if (fs::exists(ref_path)) {
            int w = 0, h = 0;
            ref = read_image_rgb(ref_path.string(), w, h);
            if (w != size.width || h != size.height) ref.clear();
            else std::printf("   reference: cached %s\n", ref_path.c_str());
        }
        if (ref.empty()) {
            AaSettings ra;
            ra.mode = AaMode::Stratified;
            ra.spp = o.ref_spp;
            RenderStats st;
            Film film = renderer.render(ra, &st);
            OutputSettings os;
            os.exr_half = false;
            write_image(film, ref_path.string(), os);
            ref = packed(film);
            std::printf("   reference: %d spp in %.2fs -> %s\n", o.ref_spp, st.render_seconds, ref_path.c_str());
        }
        {
            Film ref_film(size.width, size.height, PixelWindow{0, 0, size.width, size.height}, AovSet{});
            for (size_t i = 0; i < ref_film.beauty.size(); ++i) ref_film.beauty[i] = {ref[3 * i], ref[3 * i + 1], ref[3 * i + 2]};
            write_image(ref_film, (out / (label + "-reference.png")).string(), OutputSettings{});
        }
        const std::vector<float> ref_disp = to_display(ref, display);

        // Every setting once per round, --repeat rounds: each keeps its minimum time, and a burst of
        // load on a shared machine spreads over the settings instead of hitting one.
        std::vector<Run> runs;
        for (const AaSettings& aa : settings) {
            Run r;
            r.scene = label;
            r.aa = aa;
            runs.push_back(std::move(r));
        }
        auto measure = [&](std::vector<Run>& batch) {
            for (int round = 0; round < std::max(1, o.repeat); ++round)
                for (Run& r : batch) {
                    if (round > 0 && r.spent >= 2.0) continue;  // slow settings: fewer runs
                    RenderStats st;
                    const double cpu0 = process_cpu_seconds();
                    r.film = renderer.render(r.aa, &st);
                    const double cpu = process_cpu_seconds() - cpu0;
                    r.spent += cpu_time ? cpu : st.render_seconds;
                    r.cpu_seconds = std::min(r.cpu_seconds, cpu);
                    r.wall_seconds = std::min(r.wall_seconds, st.render_seconds);
                    r.stats = st;  // counts and image are the same every run
                }
            for (Run& r : batch) {
                r.seconds = cpu_time ? r.cpu_seconds : r.wall_seconds;
                const std::vector<float> img = packed(r.film);
                r.film = Film{};
                metrics(img, ref, r.rmse_lin, r.psnr_lin, r.relmse_lin);
                metrics(to_display(img, display), ref_disp, r.rmse_disp, r.psnr_disp, r.relmse_disp);
            }
        };
        measure(runs);
        mark_pareto(runs);

        std::printf("   %-28s %9s %10s %8s %10s %10s %8s %6s\n", "setting", "time[s]", "cam rays", "rays/px",
                    "rmse lin", "rmse disp", "psnr", "split");
        const double pixels = double(size.width) * double(size.height);
        auto report = [&](const Run& r, std::ofstream& to) {
            const double split = r.stats.pixels ? double(r.stats.pixels_subdivided) / double(r.stats.pixels) : 0.0;
            std::printf("   %-28s %9.4f %10llu %8.2f %10.5f %10.5f %8.2f %5.1f%%%s\n", describe(r.aa).c_str(), r.seconds,
                        (unsigned long long)r.stats.rays.camera, double(r.stats.rays.camera) / pixels, r.rmse_lin,
                        r.rmse_disp, r.psnr_disp, 100.0 * split, r.pareto ? "  *" : "");
            to << fmt::format("{},{},{},{:g},{},{},\"{}\",{:.6f},{},{},{:.4f},{:.6g},{:.4f},{:.6g},{:.6g},{:.4f},{:.6g},{:.5f},{},"
                              "{},{:.6f},{:.6f},{},{},{},{:.2f}\n",
                              label, aa_mode_name(r.aa.mode), pixel_filter_name(r.aa.filter),
                              r.aa.mode == AaMode::Adaptive ? r.aa.threshold : 0.f,
                              r.aa.mode == AaMode::Adaptive ? r.aa.depth : 0,
                              r.aa.mode == AaMode::Stratified ? r.aa.spp : (r.aa.mode == AaMode::Center ? 1 : 0),
                              describe(r.aa), r.seconds, r.stats.rays.camera, r.stats.rays.total(),
                              double(r.stats.rays.camera) / pixels, r.rmse_lin, r.psnr_lin, r.relmse_lin, r.rmse_disp,
                              r.psnr_disp, r.relmse_disp, split, r.pareto ? 1 : 0, o.timing, r.cpu_seconds,
                              r.wall_seconds, r.stats.rays.shadow, r.stats.rays.secondary(), r.stats.threads,
                              load_average_1min());
            to.flush();
        };
        for (const Run& r : runs) report(r, csv);

        // Targets (docs/antialiasing.md): adaptive against stratified 16 spp, corners against center.
        auto find = [&](AaMode mode, int spp) -> const Run* {
            for (const Run& r : runs)
                if (r.aa.mode == mode && (mode != AaMode::Stratified || (r.aa.spp == spp && r.aa.filter == PixelFilter::Box)))
                    return &r;
            return nullptr;
        };
        const Run* s16 = find(AaMode::Stratified, 16);
        const Run* center = find(AaMode::Center, 1);
        const Run* corners = find(AaMode::Corners, 1);
        if (s16) {
            // The sweep's thresholds are an octave apart, so its cheapest adaptive setting at the
            // target can be much better than stratified 16 (and dearer than needed). Per depth,
            // bisect the threshold between the largest one that reaches stratified 16's display
            // RMSE and the next larger one that does not (geometric means; only measured runs
            // count, so a non-monotone step just narrows the wrong way).
            if (o.target_search > 0) std::printf("   threshold search at stratified 16's display RMSE %.5f:\n", s16->rmse_disp);
            const std::vector<Run> searched = threshold_search(runs, s16->rmse_disp, o.target_search, [&](float t, int d) {
                std::vector<Run> one(1);
                one[0].scene = label;
                one[0].aa.mode = AaMode::Adaptive;
                one[0].aa.threshold = t;
                one[0].aa.depth = d;
                measure(one);
                report(one[0], search_csv);
                return one[0];
            });
            std::vector<const Run*> candidates;
            for (const Run& r : runs) candidates.push_back(&r);
            for (const Run& r : searched) candidates.push_back(&r);
            const Run* best = nullptr;
            // Also by total rays traced: a cost that does not depend on the machine's load.
            const Run* fewest = nullptr;
            for (const Run* r : candidates) {
                if (r->aa.mode != AaMode::Adaptive || r->rmse_disp > s16->rmse_disp) continue;
                if (!best || r->seconds < best->seconds) best = r;
                if (!fewest || r->stats.rays.total() < fewest->stats.rays.total()) fewest = r;
            }
            auto rays_ratio = [&](const Run& r) { return double(r.stats.rays.total()) / double(s16->stats.rays.total()); };
            if (best) {
                std::printf("   target adaptive <= 1/3 time of stratified 16 at its display RMSE %.5f%s: %s at %.3fx time "
                            "(%.3fx total rays) -> %s; fewest rays: %s at %.3fx\n",
                            s16->rmse_disp, searched.empty() ? "" : " (threshold search)", describe(best->aa).c_str(),
                            best->seconds / s16->seconds, rays_ratio(*best),
                            best->seconds <= s16->seconds / 3.0 ? "MET" : "NOT MET", describe(fewest->aa).c_str(),
                            rays_ratio(*fewest));
                // Why time and rays differ: rays per camera ray (the ray trees' size) and time per ray.
                auto tree = [](const Run& r) { return double(r.stats.rays.total()) / double(r.stats.rays.camera); };
                auto per_ray = [](const Run& r) { return 1e9 * r.seconds / double(r.stats.rays.total()); };
                std::printf("   rays per camera ray: %s %.2f, stratified 16 %.2f; time per ray %.0f ns vs %.0f ns (%.2fx)\n",
                            describe(best->aa).c_str(), tree(*best), tree(*s16), per_ray(*best), per_ray(*s16),
                            per_ray(*best) / per_ray(*s16));
                if (o.replay) {
                    for (const Run* r : {best, s16}) {
                        const ReplaySplit split = replay_split(renderer, scene, rs, r->aa, o.repeat);
                        std::printf("   replay (CPU, 1 thread): %s renders in %.4fs, its camera rays' trees alone take %.4fs:"
                                    " %.1f%% of the render is outside the ray trees\n",
                                    describe(r->aa).c_str(), split.render_seconds, split.replay_seconds,
                                    100.0 * (split.render_seconds - split.replay_seconds) / split.render_seconds);
                    }
                }
            } else {
                std::printf("   target adaptive <= 1/3 time of stratified 16 at its display RMSE %.5f: no adaptive setting "
                            "reaches it -> NOT MET\n", s16->rmse_disp);
            }
        }
        if (center && corners)
            std::printf("   target corners <= 1.1x center time: %.3fx -> %s (display RMSE center %.5f, corners %.5f)\n",
                        corners->seconds / center->seconds, corners->seconds <= 1.1 * center->seconds ? "MET" : "NOT MET",
                        center->rmse_disp, corners->rmse_disp);

        // Sample-density heat map of the default adaptive setting, and that image.
        AaSettings def;
        def.mode = AaMode::Adaptive;
        RenderSettings hs = rs;
        hs.aovs.aa_samples = true;
        hs.aa = def;
        Renderer heat_renderer(scene, hs);
        const Film heat = heat_renderer.render();
        write_heat_map(heat, def.depth, out / (label + "-adaptive-samples.png"));
        write_image(heat, (out / (label + "-adaptive.png")).string(), OutputSettings{});
        Film center_film = renderer.render(AaSettings{});
        write_image(center_film, (out / (label + "-center.png")).string(), OutputSettings{});
    }
    std::printf("wrote %s, %s\n", (out / "aa.csv").c_str(), (out / "aa_target_search.csv").c_str());

    if (o.plot) {
        const fs::path script = fs::path(WHITTED_SOURCE_DIR) / "scripts" / "plot_aa.py";
        const std::string cmd = fmt::format("{} '{}' '{}' '{}'", o.python, script.string(), (out / "aa.csv").string(), out.string());
        if (fs::exists(script) && std::system((o.python + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            if (std::system(cmd.c_str()) != 0) log_warning("bench aa: plotting failed: {}", cmd);
        } else {
            log_warning("bench aa: python3 with matplotlib not found; plot later with: {}", cmd);
        }
    }
    return 0;
}

}  // namespace

Command register_bench_aa(CLI::App& bench) {
    auto o = std::make_shared<BenchAaOptions>();
    CLI::App* app = bench.add_subcommand("aa", "Anti-aliasing: error against run time for every mode (docs/antialiasing.md)");
    app->add_option("scenes", o->scenes, "Scene files (.gltf or .glb)")->required();
    app->add_option("--width", o->width, "Image width (height from the camera aspect)")->check(CLI::Range(8, 4096))
        ->capture_default_str();
    app->add_option("--ref-spp", o->ref_spp, "Reference samples per pixel (a square number, box filter)")
        ->check(CLI::Range(1, 4096))->capture_default_str();
    app->add_option("--repeat", o->repeat, "Timed runs per setting (the minimum is reported)")->check(CLI::Range(1, 100))
        ->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--max-depth", o->max_depth, "Maximum depth of the ray tree (-1 = the scene file's, else 5)")
        ->check(CLI::Range(-1, 64))->capture_default_str();
    app->add_option("--timing", o->timing, "Time each render by process CPU time (cpu: robust on a shared machine, "
                    "exact with --threads 1) or wall-clock time (wall)")->check(CLI::IsMember({"cpu", "wall"}))
        ->capture_default_str();
    app->add_option("--out", o->out, "Output directory: aa.csv, reference/adaptive/heat-map PNGs, plots")->capture_default_str();
    app->add_option("--cache", o->cache, "Reference cache directory (default $XDG_CACHE_HOME/whitted or ~/.cache/whitted)");
    app->add_flag("--quick", o->quick, "A shorter sweep");
    app->add_option("--only", o->only, "Run only this setting of the sweep, by its printed label, e.g. "
                    "--only 'adaptive t=0.05 d=2' --only 'stratified 16 spp box' (an A/B of two builds at the target)")
        ->allow_extra_args(false);
    app->add_flag("--replay", o->replay, "For the target runs, time the render against replaying its camera rays "
                  "through the integrator in a plain loop (needs --threads 1)");
    app->add_option("--target-search", o->target_search, "Bisection steps of the adaptive threshold between the "
                    "sweep's settings around stratified 16's RMSE, per depth (0 = the sweep's settings only); "
                    "runs in <out>/aa_target_search.csv")
        ->check(CLI::Range(0, 10))->capture_default_str();
    app->add_flag("!--no-plot", o->plot, "Do not run scripts/plot_aa.py");
    app->add_option("--python", o->python, "Python interpreter with matplotlib for the plots")->capture_default_str();
    return Command{app, [o] { return run_bench_aa(*o); }};
}

}  // namespace whitted::app
