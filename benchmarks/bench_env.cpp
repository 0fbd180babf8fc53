// `whitted bench env [ASSETS...]`: how many lights to extract from an environment
// (docs/environment.md, "whitted bench env").
//
// For each asset and map: the asset rendered with N extracted lights for every N of --lights and
// with the reference N (--reference), each a scene of its own (load_scene with the environment
// and N, as `whitted render --environment MAP --env-lights N` loads it) on the same settings. Each
// N reports the RMSE of its display image (the OCIO transform `render` writes PNGs with, clamped to
// [0, 1]: 1/255 is one 8-bit code) against the reference's, its render time (the median of
// --repeat runs, interleaved over the Ns; fewer runs once an N has taken 2 s) and its shadow rays.
// The chosen default is the N of least total time whose RMSE is within 1/255 on every asset and
// map; the bench names the asset and map that rule out the next cheaper N.
//
// Then the cost of the environment's lookups (MIP lat-long for missed rays, SH9 ambient): each
// bundled scene rendered with the first map and 0 extracted lights against a plain background
// (no environment), both with the same lights, as a ratio of median times.
//
// Then the split alone, without rendering (--no-split skips it): for each of --split-maps, the
// map's build and split times, then for every threshold rule and light count the irradiance error
// of lights + ambient against the map's brute-force irradiance, at the 6 axes and at random normals
// (docs/measurements/environment.md "Threshold and light count").
//
// Writes <out>/env.csv, <out>/env_overhead.csv, <out>/env_split_cost.csv, <out>/env_split.csv, a PNG
// per asset, map and N, and (python3 with matplotlib) the error-against-time plot through
// scripts/plot_env.py.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/irradiance_check.h"
#include "benchmarks/occlusion_scene.h"
#include "benchmarks/path_reference.h"
#include "benchmarks/bench_timing.h"
#include "importers/environment_image.h"
#include "importers/scene_loader.h"
#include "core/error.h"
#include "integrator/render.h"
#include "output/image_output.h"
#include "shading/environment_map.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;

/// One display code of an 8-bit image: the tolerance the default is chosen by.
constexpr double kOneCode = 1.0 / 255.0;

struct BenchEnvOptions {
    std::vector<std::string> assets;                       ///< glTF files; empty = kDefaultAssets
    std::vector<std::string> maps{"studio", "courtyard"};  ///< environments (bundled names or files)
    std::vector<int> lights{0, 1, 4, 16, 64, 256};         ///< extracted-light counts compared
    int reference = 1024;                                  ///< the count every other is compared against
    int width = 320;                                       ///< image width in pixels (height from the camera aspect)
    int repeat = 3;                                        ///< timed runs per N (fewer once an N has taken 2 s); the median is reported
    int threads = 0;                                       ///< 0 = all cores
    std::string timing = "cpu";                            ///< "cpu": process CPU time, "wall": the render's wall time
    std::string aa = "center";                             ///< anti-aliasing mode: one centre ray keeps the error the lighting's
    float min_weight = 1.f / 255.f;                        ///< `render`'s default: what a user gets (0: every light's shadow traced)
    std::vector<std::string> overhead_scenes;              ///< scenes of the lookup-cost measurement; empty = the bundled ones
    int overhead_repeat = 7;                               ///< timed runs per scene and variant (interleaved); the median is reported
    bool overhead = true;                                  ///< measure the lookup cost at all
    std::string out = "bench-env";                         ///< output directory (CSV, images, plot)
    bool split = true;                                     ///< measure the split alone (env_split*.csv)
    std::vector<std::string> split_maps;                   ///< its maps; empty = every bundled one
    std::vector<int> split_counts{4, 16, 64, 128, 256};    ///< its light counts
    int split_normals = 100;                               ///< random normals its error is measured at (besides the 6 axes)
    std::vector<int> occlusion{0, 4, 9, 16, 25, 36, 64};   ///< --env-occlusion budgets compared (0 = off)
    int occlusion_reference = 1024;                        ///< the budget they are compared against
    std::vector<std::string> occlusion_maps{"furnace", "studio", "courtyard"};  ///< environments of the occlusion sweep
    std::vector<std::string> occlusion_scenes;             ///< its scenes; empty = the generated occlusion scene and default.glb
    bool occlusion_sweep = true;                           ///< measure the occlusion budgets at all
    int path_spp = 0;                                      ///< > 0: also against a path-traced reference of this many paths per pixel
    bool plot = true;                                      ///< run scripts/plot_env.py afterwards when possible
    std::string python = default_python();                        ///< interpreter with matplotlib for the plot
};

/// Assets of the default run, under assets/gltf/<name>/glTF-Binary/<name>.glb, and the default scene.
const char* const kDefaultAssets[] = {"Duck", "MetalRoughSpheresNoTextures", "GlassHurricaneCandleHolder",
                                      "SpecularTest"};

std::vector<std::string> default_assets() {
    const fs::path assets = fs::path(WHITTED_SOURCE_DIR) / "assets";
    std::vector<std::string> out;
    for (const char* name : kDefaultAssets)
        out.push_back((assets / "gltf" / name / "glTF-Binary" / (std::string(name) + ".glb")).string());
    out.push_back((assets / "scenes" / "default.glb").string());
    return out;
}

/// The bundled scenes: assets/scenes/*.json in name order, then default.glb.
std::vector<std::string> bundled_scenes() {
    const fs::path dir = fs::path(WHITTED_SOURCE_DIR) / "assets" / "scenes";
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && e.path().extension() == ".json") out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    out.push_back((dir / "default.glb").string());
    return out;
}

std::string label_of(const std::string& path) { return fs::path(path).stem().string(); }

/// The bench's render settings for `scene`: its file's settings, then the bench's size, threads,
/// anti-aliasing and min weight (what the file sets of the latter wins, as in `render`).
/// `occlusion`: the --env-occlusion budget (the lookup-cost measurement turns it off).
RenderSettings bench_settings(const Scene& scene, const BenchEnvOptions& o, int occlusion = kDefaultEnvOcclusion) {
    RenderSettings rs;
    rs.integrator.min_weight = o.min_weight;
    rs.integrator.env_occlusion = occlusion;
    apply_scene_settings(scene.settings, rs);
    rs.width = o.width;
    rs.height = 0;
    rs.threads = o.threads;
    rs.progress = false;
    rs.aa = AaSettings{};
    rs.aa.mode = parse_aa_mode(o.aa);
    return rs;
}

/// One scene to time: its renderer and the runs so far.
struct Timed {
    std::unique_ptr<Scene> scene;
    std::unique_ptr<Renderer> renderer;
    std::vector<double> cpu, wall;  ///< seconds of each run
    double spent = 0.0;             ///< seconds spent rendering it (the 2 s budget)
    RenderStats stats;              ///< of the last run (every run traces the same rays)
    Film film;                      ///< of the last run (every run gives the same image)

    Timed(Scene s, const BenchEnvOptions& o, int occlusion = kDefaultEnvOcclusion)
        : scene(std::make_unique<Scene>(std::move(s))),
          renderer(std::make_unique<Renderer>(*scene, bench_settings(*scene, o, occlusion))) {}

    /// Renders once and records its times.
    void run(bool cpu_timing) {
        const double cpu0 = process_cpu_seconds();
        film = renderer->render(&stats);
        cpu.push_back(process_cpu_seconds() - cpu0);
        wall.push_back(stats.render_seconds);
        spent += cpu_timing ? cpu.back() : wall.back();
    }
    /// The reported time: the median run by the chosen clock.
    double seconds(bool cpu_timing) const { return median(cpu_timing ? cpu : wall); }
};

/// Renders every scene of `batch` `repeat` times, one round over the batch at a time, so that a
/// burst of load on a shared machine spreads over the batch; with `budget` > 0 a scene that has
/// taken that many seconds is not run again.
void time_interleaved(std::vector<Timed*> batch, int repeat, double budget, bool cpu_timing) {
    for (int round = 0; round < std::max(1, repeat); ++round)
        for (Timed* t : batch)
            if (round == 0 || budget <= 0.0 || t->spent < budget) t->run(cpu_timing);
}

/// time_interleaved over every scene of `timed`, with the sweeps' 2 s budget per scene.
void time_all(std::vector<Timed>& timed, int repeat, bool cpu_timing) {
    std::vector<Timed*> batch;
    for (Timed& t : timed) batch.push_back(&t);
    time_interleaved(batch, repeat, 2.0, cpu_timing);
}

/// What one N measured on one asset and map.
struct Row {
    std::string asset, map;
    int lights = 0;             ///< N asked for
    size_t extracted = 0;       ///< lights the split gave (fewer when the map has less to extract)
    double rmse_display = 0.0;  ///< against the reference N, display values 0..1
    double rmse_linear = 0.0;
    double max_display = 0.0;   ///< largest channel difference, display values
    double seconds = 0.0, cpu_seconds = 0.0, wall_seconds = 0.0;
    size_t runs = 0;
    RenderStats stats;
};

size_t environment_light_count(const Scene& scene) {
    return size_t(std::count_if(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return l.from_environment; }));
}

/// Sum of the rows' times at `n`, and whether every row at `n` is within one code.
struct Candidate {
    int lights = 0;
    double seconds = 0.0;
    bool within = true;
    const Row* worst = nullptr;  ///< the row of largest RMSE at this N
};

std::vector<Candidate> candidates(const std::vector<int>& counts, const std::vector<Row>& rows) {
    std::vector<Candidate> out;
    for (const int n : counts) {
        Candidate c;
        c.lights = n;
        for (const Row& r : rows) {
            if (r.lights != n) continue;
            c.seconds += r.seconds;
            c.within = c.within && r.rmse_display <= kOneCode;
            if (!c.worst || r.rmse_display > c.worst->rmse_display) c.worst = &r;
        }
        out.push_back(c);
    }
    return out;
}

/// Measures and prints the extracted-light sweep; returns its rows.
std::vector<Row> light_sweep(const BenchEnvOptions& o, const std::vector<int>& counts, const fs::path& out) {
    const bool cpu_timing = o.timing == "cpu";
    const DisplayTransform display(ColorSettings{});
    std::ofstream csv(out / "env.csv");
    csv << "asset,map,lights,extracted_lights,reference,rmse_display,rmse_display_codes,rmse_linear,max_display,"
           "within_one_code,seconds,timing,runs,cpu_seconds,wall_seconds,shadow_rays,shadow_skipped_dim,total_rays,"
           "width,height,threads,load\n";
    std::vector<Row> rows;
    for (const std::string& asset : o.assets.empty() ? default_assets() : o.assets) {
        for (const std::string& map : o.maps) {
            std::vector<Timed> timed;
            timed.reserve(counts.size());
            for (const int n : counts) {
                ImportOptions io;
                io.environment = map;
                io.environment_lights = n;
                timed.emplace_back(load_scene(asset, io), o);
            }
            const ImageSize size = timed.front().renderer->image_size();
            std::printf("== %s / %s: %dx%d, %zu triangles, %s, %s time, load %.2f\n", label_of(asset).c_str(),
                        map.c_str(), size.width, size.height, timed.front().scene->instanced_triangle_count(),
                        o.aa.c_str(), cpu_timing ? "process CPU" : "wall", load_average_1min());
            time_all(timed, o.repeat, cpu_timing);

            const size_t ref_index = size_t(std::find(counts.begin(), counts.end(), o.reference) - counts.begin());
            const std::vector<float> ref_linear = packed_rgb(timed[ref_index].film);
            const std::vector<float> ref_display = display_rgb(ref_linear, display);
            const double ref_seconds = timed[ref_index].seconds(cpu_timing);
            std::printf("   %6s %6s %10s %6s %10s %9s %9s %4s %12s %7s\n", "N", "lights", "rmse disp", "codes", "rmse lin",
                        "max disp", "time[s]", "runs", "shadow rays", "vs ref");
            for (size_t k = 0; k < counts.size(); ++k) {
                Timed& t = timed[k];
                Row r;
                r.asset = label_of(asset);
                r.map = map;
                r.lights = counts[k];
                r.extracted = environment_light_count(*t.scene);
                const std::vector<float> linear = packed_rgb(t.film);
                const std::vector<float> disp = display_rgb(linear, display);
                r.rmse_display = rmse(disp, ref_display);
                r.rmse_linear = rmse(linear, ref_linear);
                r.max_display = max_abs_difference(disp, ref_display);
                r.seconds = t.seconds(cpu_timing);
                r.cpu_seconds = median(t.cpu);
                r.wall_seconds = median(t.wall);
                r.runs = t.cpu.size();
                r.stats = t.stats;
                write_image(t.film, (out / fmt::format("{}-{}-{}.png", r.asset, label_of(map), r.lights)).string(),
                            OutputSettings{});
                t.film = Film{};
                std::printf("   %6d %6zu %10.5f %6.2f %10.5f %9.4f %9.4f %4zu %12llu %6.3fx%s\n", r.lights, r.extracted,
                            r.rmse_display, r.rmse_display / kOneCode, r.rmse_linear, r.max_display, r.seconds, r.runs,
                            (unsigned long long)r.stats.rays.shadow, r.seconds / ref_seconds,
                            r.rmse_display <= kOneCode ? "" : "  > 1/255");
                csv << fmt::format("{},{},{},{},{},{:.6g},{:.4f},{:.6g},{:.6g},{},{:.6f},{},{},{:.6f},{:.6f},{},{},{},{},{},{},{:.2f}\n",
                                   r.asset, r.map, r.lights, r.extracted, o.reference, r.rmse_display,
                                   r.rmse_display / kOneCode, r.rmse_linear, r.max_display,
                                   r.rmse_display <= kOneCode ? 1 : 0, r.seconds, o.timing, r.runs, r.cpu_seconds,
                                   r.wall_seconds, r.stats.rays.shadow, r.stats.rays.shadow_skipped_dim,
                                   r.stats.rays.total(), size.width, size.height, r.stats.threads, load_average_1min());
                csv.flush();
                rows.push_back(std::move(r));
            }
        }
    }
    return rows;
}

/// Prints the default the sweep chooses: the N of least total time within one code everywhere.
void print_choice(const BenchEnvOptions& o, const std::vector<int>& counts, const std::vector<Row>& rows) {
    const std::vector<Candidate> cs = candidates(counts, rows);
    const Candidate* chosen = nullptr;
    for (const Candidate& c : cs)
        if (c.within && (!chosen || c.seconds < chosen->seconds)) chosen = &c;
    const Candidate& ref = *std::find_if(cs.begin(), cs.end(), [&](const Candidate& c) { return c.lights == o.reference; });
    std::printf("== choice: total time over every asset and map, worst display RMSE against N = %d\n", o.reference);
    for (const Candidate& c : cs)
        std::printf("   N = %-5d %9.4f s (%6.3fx)  worst %.5f (%.2f codes, %s / %s)%s\n", c.lights, c.seconds,
                    c.seconds / ref.seconds, c.worst->rmse_display, c.worst->rmse_display / kOneCode,
                    c.worst->asset.c_str(), c.worst->map.c_str(), c.within ? "" : "  > 1/255");
    std::printf("chosen default --env-lights: %d\n", chosen->lights);
    // What rules out the cheaper counts: the most expensive of them, and its worst asset and map.
    const Candidate* next = nullptr;
    for (const Candidate& c : cs)
        if (c.seconds < chosen->seconds && (!next || c.seconds > next->seconds)) next = &c;
    if (next)
        std::printf("   decided by %s / %s: the next cheaper N = %d is %.2f codes off (RMSE %.5f > 1/255)\n",
                    next->worst->asset.c_str(), next->worst->map.c_str(), next->lights,
                    next->worst->rmse_display / kOneCode, next->worst->rmse_display);
    else
        std::printf("   no listed N is cheaper\n");
    std::printf("   closest to the limit at N = %d: %s / %s, %.2f codes (RMSE %.5f)\n", chosen->lights,
                chosen->worst->asset.c_str(), chosen->worst->map.c_str(), chosen->worst->rmse_display / kOneCode,
                chosen->worst->rmse_display);
    const auto current = std::find_if(cs.begin(), cs.end(), [](const Candidate& c) { return c.lights == kDefaultEnvironmentLights; });
    if (current != cs.end())
        std::printf("   the current default kDefaultEnvironmentLights = %d: worst %.2f codes (%s / %s), %s\n",
                    kDefaultEnvironmentLights, current->worst->rmse_display / kOneCode, current->worst->asset.c_str(),
                    current->worst->map.c_str(), current->within ? "within 1/255" : "NOT within 1/255");
}

/// The environment's lookup cost: each scene with `map` and no extracted light against no
/// environment, both with the same lights (a scene without lights gets the default light only
/// when it has no environment; it is left out of the plain render too).
void lookup_overhead(const BenchEnvOptions& o, const std::string& map, const fs::path& out) {
    const bool cpu_timing = o.timing == "cpu";
    std::ofstream csv(out / "env_overhead.csv");
    csv << "scene,map,plain_seconds,env_seconds,ratio,target_met,timing,runs,lights,environment_ambient,"
           "environment_visible,plain_total_rays,env_total_rays,width,height,threads,load\n";
    std::printf("== lookup cost: %s with 0 extracted lights against a plain background, %s time, median of %d, load %.2f\n",
                map.c_str(), cpu_timing ? "process CPU" : "wall", o.overhead_repeat, load_average_1min());
    std::printf("   %-24s %10s %10s %7s %6s  %s\n", "scene", "plain[s]", "env[s]", "ratio", "lights", "environment terms");
    for (const std::string& path : o.overhead_scenes.empty() ? bundled_scenes() : o.overhead_scenes) {
        ImportOptions with;
        with.environment = map;
        with.environment_lights = 0;
        Scene env_scene = load_scene(path, with);
        ImportOptions without;
        without.no_environment = true;
        Scene plain_scene = load_scene(path, without);
        const auto is_default = [](const Light& l) { return l.is_default; };
        if (std::none_of(env_scene.lights.begin(), env_scene.lights.end(), is_default))
            std::erase_if(plain_scene.lights, is_default);
        const size_t lights = env_scene.lights.size();
        Timed plain(std::move(plain_scene), o, 0), env(std::move(env_scene), o, 0);
        time_interleaved({&plain, &env}, o.overhead_repeat, 0.0, cpu_timing);
        const RenderSettings rs = bench_settings(*env.scene, o, 0);
        const std::string terms = fmt::format("{}{}", rs.integrator.environment_visible ? "background" : "(hidden)",
                                              rs.integrator.environment_ambient ? " + SH9 ambient" : " (file's ambient)");
        const double ratio = env.seconds(cpu_timing) / plain.seconds(cpu_timing);
        std::printf("   %-24s %10.4f %10.4f %6.3fx %6zu  %s%s\n", label_of(path).c_str(), plain.seconds(cpu_timing),
                    env.seconds(cpu_timing), ratio, lights, terms.c_str(), ratio <= 1.10 ? "" : "  > 1.10");
        const ImageSize size = env.renderer->image_size();
        csv << fmt::format("{},{},{:.6f},{:.6f},{:.4f},{},{},{},{},{},{},{},{},{},{},{},{:.2f}\n", label_of(path), map,
                           plain.seconds(cpu_timing), env.seconds(cpu_timing), ratio, ratio <= 1.10 ? 1 : 0, o.timing,
                           env.cpu.size(), lights, rs.integrator.environment_ambient ? 1 : 0,
                           rs.integrator.environment_visible ? 1 : 0, plain.stats.rays.total(), env.stats.rays.total(),
                           size.width, size.height, env.stats.threads, load_average_1min());
        csv.flush();
    }
}

// ---- occlusion: --env-occlusion budgets against a high budget ------------------------------------

/// What one occlusion budget measured on one scene and map.
struct OcclusionRow {
    std::string scene, map;
    int budget = 0;
    double psnr = 0.0;        ///< display values against the reference budget, dB (inf: identical)
    double rmse_codes = 0.0;  ///< the same error in 8-bit codes
    double mean_ratio = 1.0;  ///< mean linear value over the reference's
    double psnr_previous = 0.0;  ///< against the next smaller budget compared (0: none)
    double seconds = 0.0;
    RenderStats stats;
};

double psnr_of(double rmse_display) { return rmse_display > 0.0 ? 20.0 * std::log10(1.0 / rmse_display) : kInfinity; }

double mean_of(const std::vector<float>& v) {
    double sum = 0.0;
    for (const float x : v) sum += double(x);
    return v.empty() ? 0.0 : sum / double(v.size());
}

/// Issue 45's targets: each budget's image (`runs`, in the order of `budgets`, films kept) against a
/// path-traced reference of o.path_spp paths per pixel (path_reference.h) on the same renderer:
/// PSNR, mean and time against the path tracer's; the path tracer's own noise (an independent
/// image of a quarter of the paths) and its PSNR at the default budget's time.
void against_path_tracer(const BenchEnvOptions& o, const std::string& scene, const std::string& map,
                         const std::vector<int>& budgets, const std::vector<Timed>& runs,
                         const DisplayTransform& display, std::ofstream& csv, const fs::path& out) {
    const bool cpu_timing = o.timing == "cpu";
    const Renderer& renderer = *runs.front().renderer;
    if (const std::string why = path_trace_refusal(renderer); !why.empty()) {
        std::printf("   path tracer: not run (%s)\n", why.c_str());
        return;
    }
    auto trace = [&](int spp, uint64_t seed, double& seconds, PathStats& stats) {
        PathSettings ps;
        ps.spp = spp;
        ps.seed = seed;
        ps.pixel_area = o.aa != "center";
        const double cpu0 = process_cpu_seconds();
        Film film = path_trace(renderer, ps, o.threads, &stats);
        seconds = cpu_timing ? process_cpu_seconds() - cpu0 : stats.seconds;
        return film;
    };
    double path_seconds = 0.0;
    PathStats path_stats;
    const Film ref = trace(o.path_spp, 0, path_seconds, path_stats);
    write_image(ref, (out / fmt::format("occlusion-{}-{}-path{}.png", scene, label_of(map), o.path_spp)).string(),
                OutputSettings{});
    const std::vector<float> ref_linear = packed_rgb(ref);
    const std::vector<float> ref_display = display_rgb(ref_linear, display);
    const double ref_mean = mean_of(ref_linear);
    auto psnr_against_ref = [&](const Film& f) { return psnr_of(rmse(display_rgb(packed_rgb(f), display), ref_display)); };
    const int quarter = std::max(1, o.path_spp / 4);
    double quarter_seconds = 0.0;
    PathStats quarter_stats;
    const double quarter_psnr = psnr_against_ref(trace(quarter, 1, quarter_seconds, quarter_stats));
    std::printf("   path tracer: %d paths/pixel, %.3f s, %.1f M rays; %d paths/pixel (independent) against it: %.2f dB\n",
                o.path_spp, path_seconds, double(path_stats.segments) * 1e-6, quarter, quarter_psnr);
    std::printf("   %6s %9s %7s %12s   against the path tracer\n", "budget", "PSNR[dB]", "mean", "time/path");
    for (size_t k = 0; k < budgets.size(); ++k) {
        const Timed& t = runs[k];
        const std::vector<float> linear = packed_rgb(t.film);
        const double psnr = psnr_of(rmse(display_rgb(linear, display), ref_display));
        const double mean = ref_mean > 0.0 ? mean_of(linear) / ref_mean : 1.0;
        const double seconds = t.seconds(cpu_timing), ratio = seconds / path_seconds;
        std::printf("   %6d %9.2f %7.4f %12s%s\n", budgets[k], psnr, mean, fmt::format("1/{:.0f}", 1.0 / ratio).c_str(),
                    budgets[k] == kDefaultEnvOcclusion ? "  <- default" : "");
        csv << fmt::format("{},{},{},{},{:.3f},{:.5f},{:.6f},{:.6f},{:.6f},{}\n", scene, map, budgets[k], o.path_spp, psnr,
                           mean, seconds, path_seconds, ratio, o.timing);
        if (budgets[k] != kDefaultEnvOcclusion) continue;
        // The targets at the default budget, and the path tracer given the same time.
        const bool mean_met = std::abs(mean - 1.0) <= 0.05, psnr_met = psnr >= 28.0, time_met = ratio <= 1.0 / 50.0;
        const int equal_spp = std::max(1, int(std::lround(double(o.path_spp) * ratio)));
        double equal_seconds = 0.0;
        PathStats equal_stats;
        const double equal_psnr = psnr_against_ref(trace(equal_spp, 2, equal_seconds, equal_stats));
        std::printf("   targets at budget %d: mean %+.1f %% (within 5 %%: %s), %.2f dB (>= 28: %s), 1/%.0f of the path "
                    "tracer's time (<= 1/50: %s); the path tracer in the same time (%d paths/pixel, %.3f s): %.2f dB\n",
                    budgets[k], 100.0 * (mean - 1.0), mean_met ? "met" : "NOT met", psnr, psnr_met ? "met" : "NOT met",
                    1.0 / ratio, time_met ? "met" : "NOT met", equal_spp, equal_seconds, equal_psnr);
    }
    csv.flush();
}

/// Renders every scene under every map at each budget and compares the display images with the
/// reference budget's; prints the cheapest budget within 40 dB everywhere.
void occlusion_sweep(const BenchEnvOptions& o, const fs::path& out) {
    const bool cpu_timing = o.timing == "cpu";
    const DisplayTransform display(ColorSettings{});
    std::vector<int> budgets = o.occlusion;
    budgets.push_back(o.occlusion_reference);
    std::sort(budgets.begin(), budgets.end());
    budgets.erase(std::unique(budgets.begin(), budgets.end()), budgets.end());
    std::vector<std::string> scenes = o.occlusion_scenes;
    if (scenes.empty()) {
        const fs::path generated = out / "occlusion.glb";
        const size_t triangles = write_occlusion_scene(generated);
        std::printf("== occlusion scene: %s (%zu triangles)\n", generated.c_str(), triangles);
        scenes = {generated.string(), (fs::path(WHITTED_SOURCE_DIR) / "assets" / "scenes" / "default.glb").string()};
    }
    std::ofstream csv(out / "env_occlusion.csv");
    csv << "scene,map,budget,reference,psnr_display,rmse_display_codes,mean_ratio,psnr_previous,seconds,timing,runs,"
           "occlusion_rays,occlusion_skipped_dim,reflection_rays,total_rays,width,height,threads,load\n";
    std::ofstream path_csv;
    if (o.path_spp > 0) {
        path_csv.open(out / "env_path_reference.csv");
        path_csv << "scene,map,budget,path_spp,psnr_display,mean_ratio,seconds,path_seconds,time_ratio,timing\n";
    }
    std::vector<OcclusionRow> rows;
    for (const std::string& path : scenes) {
        for (const std::string& map : o.occlusion_maps) {
            ImportOptions io;
            io.environment = map;
            const Scene loaded = load_scene(path, io);
            std::vector<Timed> timed;
            timed.reserve(budgets.size());
            for (const int b : budgets) timed.emplace_back(Scene(loaded), o, b);
            const ImageSize size = timed.front().renderer->image_size();
            std::printf("== occlusion: %s / %s: %dx%d, %s, %s time, load %.2f\n", label_of(path).c_str(), map.c_str(),
                        size.width, size.height, o.aa.c_str(), cpu_timing ? "process CPU" : "wall", load_average_1min());
            time_all(timed, o.repeat, cpu_timing);
            const size_t ref_index = size_t(std::find(budgets.begin(), budgets.end(), o.occlusion_reference) - budgets.begin());
            const std::vector<float> ref_linear = packed_rgb(timed[ref_index].film);
            const std::vector<float> ref_display = display_rgb(ref_linear, display);
            const double ref_mean = mean_of(ref_linear);
            std::printf("   %6s %9s %7s %7s %10s %9s %13s %12s\n", "budget", "PSNR[dB]", "codes", "mean", "PSNR prev",
                        "time[s]", "occl. rays", "refl. rays");
            std::vector<float> previous;
            for (size_t k = 0; k < budgets.size(); ++k) {
                Timed& t = timed[k];
                OcclusionRow r;
                r.scene = label_of(path);
                r.map = map;
                r.budget = budgets[k];
                const std::vector<float> linear = packed_rgb(t.film);
                const std::vector<float> disp = display_rgb(linear, display);
                const double e = rmse(disp, ref_display);
                r.psnr = psnr_of(e);
                r.rmse_codes = e / kOneCode;
                r.mean_ratio = ref_mean > 0.0 ? mean_of(linear) / ref_mean : 1.0;
                r.psnr_previous = previous.empty() ? 0.0 : psnr_of(rmse(disp, previous));
                r.seconds = t.seconds(cpu_timing);
                r.stats = t.stats;
                write_image(t.film, (out / fmt::format("occlusion-{}-{}-{}.png", r.scene, label_of(map), r.budget)).string(),
                            OutputSettings{});
                if (o.path_spp <= 0) t.film = Film{};  // kept for the path-traced comparison
                previous = disp;
                std::printf("   %6d %9.2f %7.2f %7.4f %10.2f %9.4f %13llu %12llu\n", r.budget, r.psnr, r.rmse_codes,
                            r.mean_ratio, r.psnr_previous, r.seconds, (unsigned long long)r.stats.rays.occlusion,
                            (unsigned long long)r.stats.rays.reflection);
                csv << fmt::format("{},{},{},{},{:.3f},{:.4f},{:.5f},{:.3f},{:.6f},{},{},{},{},{},{},{},{},{},{:.2f}\n", r.scene,
                                   r.map, r.budget, o.occlusion_reference, r.psnr, r.rmse_codes, r.mean_ratio,
                                   r.psnr_previous, r.seconds, o.timing, t.cpu.size(), r.stats.rays.occlusion,
                                   r.stats.rays.occlusion_skipped_dim, r.stats.rays.reflection, r.stats.rays.total(),
                                   size.width, size.height, r.stats.threads, load_average_1min());
                csv.flush();
                rows.push_back(std::move(r));
            }
            if (o.path_spp > 0) against_path_tracer(o, label_of(path), map, budgets, timed, display, path_csv, out);
        }
    }
    // The cheapest budget within 40 dB of the reference on every scene and map.
    std::printf("== occlusion budget: the least total time with PSNR >= 40 dB against budget %d everywhere\n",
                o.occlusion_reference);
    int chosen = -1;
    for (const int b : budgets) {
        double seconds = 0.0, worst = kInfinity;
        const OcclusionRow* worst_row = nullptr;
        for (const OcclusionRow& r : rows) {
            if (r.budget != b) continue;
            seconds += r.seconds;
            if (r.psnr < worst) worst = r.psnr, worst_row = &r;
        }
        const bool within = worst >= 40.0;
        if (within && chosen < 0) chosen = b;
        std::printf("   %6d %9.4f s  worst %6.2f dB%s%s\n", b, seconds, worst,
                    worst_row ? fmt::format(" ({} / {})", worst_row->scene, worst_row->map).c_str() : "",
                    b == kDefaultEnvOcclusion ? "  <- kDefaultEnvOcclusion" : "");
    }
    std::printf("   chosen: %d (kDefaultEnvOcclusion = %d)\n", chosen, kDefaultEnvOcclusion);
}

// ---- the split alone: threshold rule and light count against irradiance error ----------------------

/// CPU time of the calling thread, seconds.
double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// For every map: build and split costs (thread CPU time); then per threshold rule and light count
/// the worst relative irradiance error of lights + ambient at the 6 axes of studio and courtyard
/// (those among the maps), and the largest and RMS error at random normals over every map.
void split_table(const BenchEnvOptions& o, const fs::path& out) {
    const std::vector<std::string> names = o.split_maps.empty() ? bundled_environment_names() : o.split_maps;
    const std::vector<Vec3f> axes{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const std::vector<Vec3f> randoms = random_directions(o.split_normals, 29);
    const std::vector<float> factors{0.f, 1.f / 16.f, 0.125f, 0.25f, 0.5f, 1.f, 2.f, 4.f};  // 0 = the default rule
    std::ofstream cost(out / "env_split_cost.csv");
    cost << "map,build_ms,split_ms_n16,split_ms_n128,split_ms_n256,bytes\n";
    std::vector<EnvironmentMap> maps;
    maps.reserve(names.size());
    for (const std::string& name : names) {
        std::vector<std::string> warnings;
        Environment env;
        env.image = std::make_shared<EnvironmentImage>(
            load_environment_image(resolve_environment_name(name), size_t(1) << 30, warnings));
        const double t0 = thread_seconds();
        maps.emplace_back(env, 1);
        const double t1 = thread_seconds();
        maps.back().split(16);
        const double t2 = thread_seconds();
        maps.back().split(128);
        const double t3 = thread_seconds();
        maps.back().split(256);
        const double t4 = thread_seconds();
        cost << fmt::format("{},{:.0f},{:.0f},{:.0f},{:.0f},{}\n", label_of(name), 1e3 * (t1 - t0), 1e3 * (t2 - t1),
                            1e3 * (t3 - t2), 1e3 * (t4 - t3), maps.back().bytes());
    }
    std::vector<std::vector<Color>> axis_ref, random_ref;
    for (const EnvironmentMap& map : maps) {
        axis_ref.emplace_back();
        random_ref.emplace_back();
        for (const Vec3f& n : axes) axis_ref.back().push_back(map.brute_force_irradiance(n));
        for (const Vec3f& n : randoms) random_ref.back().push_back(map.brute_force_irradiance(n));
    }
    std::ofstream table(out / "env_split.csv");
    table << "factor,correct_ambient,lights,axes_worst_studio_courtyard_pct,random_max_all_pct,random_rms_all_pct\n";
    for (const bool correct : {true, false})
        for (const float factor : factors) {
            if (!correct && factor != 0.f) continue;
            for (const int n : o.split_counts) {
                SplitSettings settings;
                settings.lights = n;
                settings.threshold_factor = factor;
                settings.correct_ambient = correct;
                float axes_worst = 0.f, random_max = 0.f;
                double squares = 0;
                for (size_t m = 0; m < maps.size(); ++m) {
                    const EnvironmentLighting lighting = maps[m].split(settings);
                    if (label_of(names[m]) == "studio" || label_of(names[m]) == "courtyard")
                        for (size_t i = 0; i < axes.size(); ++i)
                            axes_worst = std::max(axes_worst, max_relative_error(lighting.irradiance(axes[i]), axis_ref[m][i]));
                    for (size_t i = 0; i < randoms.size(); ++i) {
                        const Color e = lighting.irradiance(randoms[i]);
                        random_max = std::max(random_max, max_relative_error(e, random_ref[m][i]));
                        for (int c = 0; c < 3; ++c)
                            squares += std::pow((e[c] - random_ref[m][i][c]) / random_ref[m][i][c], 2.0);
                    }
                }
                const double samples = std::max(1.0, 3.0 * double(randoms.size() * maps.size()));
                table << fmt::format("{},{},{},{:.2f},{:.2f},{:.2f}\n",
                                     factor == 0.f ? "2/sqrt(n)" : fmt::format("{:g}", factor), correct ? "yes" : "no",
                                     n, 100.0 * axes_worst, 100.0 * random_max, 100.0 * std::sqrt(squares / samples));
            }
        }
    if (!cost || !table) throw Error(fmt::format("bench env: cannot write the split tables in {}", out.string()));
    std::printf("split: %zu maps, %zu light counts, %d random normals\n", maps.size(), o.split_counts.size(),
                o.split_normals);
}

int run_bench_env(const BenchEnvOptions& o) {
    if (o.maps.empty()) throw Error("bench env: --maps: give at least one environment");
    if (o.lights.empty()) throw Error("bench env: --lights: give at least one count");
    for (const int n : o.split_counts)
        if (n < 0) throw Error(fmt::format("bench env: --split-counts: counts are 0 or more (got {})", n));
    for (const int n : o.lights)
        if (n < 0) throw Error(fmt::format("bench env: --lights: counts are 0 or more (got {})", n));
    for (const int n : o.occlusion)
        if (n < 0 || n > kMaxEnvOcclusion)
            throw Error(fmt::format("bench env: --occlusion: budgets are 0 to {} (got {})", kMaxEnvOcclusion, n));
    (void)parse_aa_mode(o.aa);
    const fs::path out(o.out);
    fs::create_directories(out);
    // Every count once, the reference among them, in increasing order.
    std::vector<int> counts = o.lights;
    counts.push_back(o.reference);
    std::sort(counts.begin(), counts.end());
    counts.erase(std::unique(counts.begin(), counts.end()), counts.end());

    const std::vector<Row> rows = light_sweep(o, counts, out);
    print_choice(o, counts, rows);
    if (o.overhead) lookup_overhead(o, o.maps.front(), out);
    if (o.occlusion_sweep) occlusion_sweep(o, out);
    if (o.split) split_table(o, out);
    const std::string overhead_csv = o.overhead ? ", " + (out / "env_overhead.csv").string() : "";
    const std::string split_csv =
        o.split ? ", " + (out / "env_split_cost.csv").string() + ", " + (out / "env_split.csv").string() : "";
    std::printf("wrote %s%s%s\n", (out / "env.csv").c_str(), overhead_csv.c_str(), split_csv.c_str());
    if (o.plot) run_plot_script(o.python, "plot_env.py", out / "env.csv", out, "bench env");
    return 0;
}

}  // namespace

Command register_bench_env(CLI::App& bench) {
    auto o = std::make_shared<BenchEnvOptions>();
    CLI::App* app = bench.add_subcommand(
        "env", "Environment lights: display error of N extracted lights against the reference N, and their time "
               "(docs/environment.md)");
    app->add_option("assets", o->assets, "glTF files (default: Duck, MetalRoughSpheresNoTextures, "
                    "GlassHurricaneCandleHolder, SpecularTest and assets/scenes/default.glb)");
    app->add_option("--maps", o->maps, "Environments, comma-separated (bundled names or files)")->delimiter(',')
        ->capture_default_str();
    app->add_option("--lights", o->lights, "Extracted-light counts to compare, comma-separated")->delimiter(',')
        ->capture_default_str();
    app->add_option("--reference", o->reference, "The count every other is compared against")
        ->check(CLI::Range(0, 65536))->capture_default_str();
    app->add_option("--width", o->width, "Image width (height from the camera aspect)")->check(CLI::Range(8, 4096))
        ->capture_default_str();
    app->add_option("--repeat", o->repeat, "Timed runs per count (the median is reported; fewer once a count has "
                    "taken 2 s)")->check(CLI::Range(1, 100))->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--timing", o->timing, "Time each render by process CPU time (cpu: robust on a shared machine, "
                    "exact with --threads 1) or wall-clock time (wall)")->check(CLI::IsMember({"cpu", "wall"}))
        ->capture_default_str();
    app->add_option("--aa", o->aa, "Anti-aliasing mode of every render")
        ->check(CLI::IsMember({"center", "corners", "adaptive", "stratified"}))->capture_default_str();
    app->add_option("--min-weight", o->min_weight, "Lights and secondary rays below this weight are not traced "
                    "(as `whitted render --min-weight`, whose default this is; 0 = every shadow ray)")->check(CLI::Range(0.0, 1.0))->capture_default_str();
    app->add_option("--overhead-scenes", o->overhead_scenes, "Scenes of the lookup-cost measurement (default: "
                    "assets/scenes/*.json and default.glb)");
    app->add_option("--overhead-repeat", o->overhead_repeat, "Timed runs per scene and variant of the lookup-cost "
                    "measurement (the median is reported)")->check(CLI::Range(1, 100))->capture_default_str();
    app->add_flag("!--no-overhead", o->overhead, "Skip the lookup-cost measurement");
    app->add_flag("!--no-split", o->split, "Skip the split measurement (threshold rule and light count against "
                  "irradiance error, no rendering)");
    app->add_option("--split-maps", o->split_maps, "Environments of the split measurement, comma-separated (default: "
                    "every bundled one)")->delimiter(',');
    app->add_option("--split-counts", o->split_counts, "Light counts of the split measurement, comma-separated")
        ->delimiter(',')->capture_default_str();
    app->add_option("--split-normals", o->split_normals, "Random normals the split's error is measured at (besides "
                    "the 6 axes)")->check(CLI::Range(1, 100000))->capture_default_str();
    app->add_option("--out", o->out, "Output directory: env.csv, env_overhead.csv, env_split*.csv, PNGs, plot")
        ->capture_default_str();
    app->add_option("--occlusion", o->occlusion, "--env-occlusion budgets to compare, comma-separated (0 = off)")
        ->delimiter(',')->capture_default_str();
    app->add_option("--occlusion-reference", o->occlusion_reference, "The budget every other is compared against")
        ->check(CLI::Range(1, kMaxEnvOcclusion))->capture_default_str();
    app->add_option("--occlusion-maps", o->occlusion_maps, "Environments of the occlusion sweep, comma-separated")
        ->delimiter(',')->capture_default_str();
    app->add_option("--occlusion-scenes", o->occlusion_scenes, "Scenes of the occlusion sweep (default: the generated "
                    "occlusion scene, written to the output directory, and assets/scenes/default.glb)")->delimiter(',');
    app->add_flag("!--no-occlusion", o->occlusion_sweep, "Skip the occlusion sweep");
    app->add_option("--path-reference", o->path_spp, "Also compare the occlusion sweep's budgets against a "
                    "path-traced reference of this many paths per pixel (0 = not; environment-lit scenes without "
                    "punctual lights; writes env_path_reference.csv)")->check(CLI::Range(0, 1 << 20))->capture_default_str();
    app->add_flag("!--no-plot", o->plot, "Do not run scripts/plot_env.py");
    app->add_option("--python", o->python, "Python interpreter with matplotlib for the plot")->capture_default_str();
    return Command{app, [o] { return run_bench_env(*o); }};
}

}  // namespace whitted::app
