// `whitted bench materials`: what each glTF material extension costs on its sample
// (docs/performance.md, "whitted bench materials").
//
// For each extension (material_samples.h lists them): its sample, the bundled Khronos file where
// there is one (ClearCoatTest, AnisotropyRotationTest), else a generated row of 5 spheres written
// into --out. The sample is loaded once; a copy of the Scene has the extension removed from every
// material (its fields back to Material's defaults; specular-glossiness keeps the core values the
// importer set from it). Both are rendered as `whitted render` would at --width x --height, --repeat
// times interleaved (with, without, with, ...), and compared: median wall-clock seconds, the ratio
// with / without (the median of each run's pair; target <= 1.3, printed as PASS or MISS, never
// asserted), the same per traced ray, the kernels the renderer
// selected, rays by kind, and the mean absolute difference of the two images (linear, over pixels
// and channels); besides, each side's build time (the Renderer: scene view, environment prefilter,
// accelerator), which the ratio leaves out. Writes <out>/materials.csv and the two images of each
// extension as PNGs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/material_samples.h"
#include "core/error.h"
#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"
#include "output/image_output.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kRatioTarget = 1.3;  ///< render time with the extension / without it

struct BenchMaterialsOptions {
    std::string out = "bench-materials";  ///< generated samples, materials.csv, the images
    int repeat = 3;                       ///< interleaved runs per side; the median is reported
    int width = 320;                      ///< render size, pixels
    int height = 240;
    int threads = 0;                      ///< render threads (0 = all cores)
    std::vector<std::string> only;        ///< extensions to measure (empty: all)
    bool generated = false;               ///< generated samples for clearcoat and anisotropy too
};

/// The bundled Khronos sample of an extension, when it has one and the file is there.
std::optional<fs::path> bundled_sample(const std::string& extension) {
    const fs::path gltf = fs::path(WHITTED_SOURCE_DIR) / "assets" / "gltf";
    fs::path p;
    if (extension == "clearcoat") p = gltf / "ClearCoatTest" / "glTF-Binary" / "ClearCoatTest.glb";
    else if (extension == "anisotropy") p = gltf / "AnisotropyRotationTest" / "glTF-Binary" / "AnisotropyRotationTest.glb";
    if (p.empty() || !fs::exists(p)) return std::nullopt;
    return p;
}

/// Whether material `m` uses `extension` (the value that switches it on).
bool uses(const Material& m, const std::string& extension) {
    if (extension == "clearcoat") return m.clearcoat > 0.f;
    if (extension == "sheen") return m.sheen_color != Color(0.f);
    if (extension == "iridescence") return m.iridescence > 0.f;
    if (extension == "anisotropy") return m.anisotropy_strength > 0.f;
    if (extension == "dispersion") return m.dispersion > 0.f;
    if (extension == "diffuse_transmission") return m.diffuse_transmission > 0.f;
    return m.specular_glossiness;
}

/// `m` without `extension`: the extension's fields back to Material's defaults. Specular-glossiness
/// keeps the core fields the importer set from it (diffuse as base colour, metallic 0, roughness
/// 1 - glossiness), so what is removed is its specular colour as F0.
void remove_extension(Material& m, const std::string& extension) {
    const Material d;
    if (extension == "clearcoat") {
        m.clearcoat = d.clearcoat;
        m.clearcoat_texture = d.clearcoat_texture;
        m.clearcoat_roughness = d.clearcoat_roughness;
        m.clearcoat_roughness_texture = d.clearcoat_roughness_texture;
        m.clearcoat_normal_texture = d.clearcoat_normal_texture;
    } else if (extension == "sheen") {
        m.sheen_color = d.sheen_color;
        m.sheen_color_texture = d.sheen_color_texture;
        m.sheen_roughness = d.sheen_roughness;
        m.sheen_roughness_texture = d.sheen_roughness_texture;
    } else if (extension == "iridescence") {
        m.iridescence = d.iridescence;
        m.iridescence_texture = d.iridescence_texture;
        m.iridescence_ior = d.iridescence_ior;
        m.iridescence_thickness_min = d.iridescence_thickness_min;
        m.iridescence_thickness_max = d.iridescence_thickness_max;
        m.iridescence_thickness_texture = d.iridescence_thickness_texture;
    } else if (extension == "anisotropy") {
        m.anisotropy_strength = d.anisotropy_strength;
        m.anisotropy_rotation = d.anisotropy_rotation;
        m.anisotropy_texture = d.anisotropy_texture;
    } else if (extension == "dispersion") {
        m.dispersion = d.dispersion;
    } else if (extension == "diffuse_transmission") {
        m.diffuse_transmission = d.diffuse_transmission;
        m.diffuse_transmission_texture = d.diffuse_transmission_texture;
        m.diffuse_transmission_color = d.diffuse_transmission_color;
        m.diffuse_transmission_color_texture = d.diffuse_transmission_color_texture;
    } else if (extension == "specular_glossiness") {
        m.specular_glossiness = d.specular_glossiness;
        m.sg_specular = d.sg_specular;
        m.glossiness = d.glossiness;
        m.specular_glossiness_texture = d.specular_glossiness_texture;
    }
}

/// The kernel in a few letters for the table: "general", or what it traces ("direct", "refl",
/// "refr"), then "tex" with per-hit attributes and "layers" with the layered materials.
std::string short_kernel(const KernelFeatures& k) {
    if (k == kGeneralKernel) return "general";
    std::string s = k.transmission ? "refr" : k.mirror ? "refl" : "direct";
    if (k.attributes) s += "+tex";
    if (k.layers) s += "+layers";
    return s;
}

/// One side of a comparison: the scene rendered with or without the extension.
struct Side {
    std::unique_ptr<Renderer> renderer;
    Film film;
    RenderStats stats;              ///< of the last run
    std::vector<double> seconds;    ///< wall clock of each run
};

/// The settings `whitted render` starts from, at the bench's size and threads.
RenderSettings bench_settings(const Scene& scene, const BenchMaterialsOptions& o) {
    RenderSettings rs = command_line_render_settings();
    apply_scene_settings(scene.settings, rs);
    rs.width = o.width;
    rs.height = o.height;
    rs.threads = o.threads;
    rs.progress = false;
    return rs;
}

/// Mean absolute difference of two films' beauty (linear, over pixels and channels), the largest
/// one, and how many pixels differ at all.
struct Difference {
    double mean_abs = 0.0, max_abs = 0.0;
    uint64_t pixels = 0;
};

Difference difference(const Film& a, const Film& b) {
    Difference d;
    if (a.beauty.size() != b.beauty.size() || a.beauty.empty()) return d;
    double sum = 0.0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            const double e = std::abs(double(a.beauty[i][c]) - double(b.beauty[i][c]));
            sum += e;
            d.max_abs = std::max(d.max_abs, e);
            differs |= a.beauty[i][c] != b.beauty[i][c];
        }
        d.pixels += differs ? 1 : 0;
    }
    d.mean_abs = sum / (3.0 * double(a.beauty.size()));
    return d;
}

const char* verdict(double ratio) { return ratio <= kRatioTarget ? "PASS" : "MISS"; }

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

/// The extensions to measure, in the bench's order; throws for a name --only does not know.
std::vector<std::string> selected(const BenchMaterialsOptions& o) {
    const std::vector<std::string>& all = material_sample_extensions();
    for (const std::string& name : o.only)
        if (std::find(all.begin(), all.end(), name) == all.end())
            throw Error(fmt::format("bench materials: --only: unknown extension '{}' (available: {})", name, joined(all)));
    std::vector<std::string> out;
    for (const std::string& name : all)
        if (o.only.empty() || std::find(o.only.begin(), o.only.end(), name) != o.only.end()) out.push_back(name);
    return out;
}

int run_bench_materials(const BenchMaterialsOptions& o) {
    const std::vector<std::string> extensions = selected(o);
    const fs::path out(o.out);
    fs::create_directories(out);
    std::ofstream csv(out / "materials.csv");
    csv << "extension,gltf_extension,sample,generated,materials_with,materials,triangles,width,height,threads,repeat,"
           "kernel_with,kernel_without,build_seconds_with,build_seconds_without,seconds_with,seconds_without,ratio,ratio_target,verdict,ratio_per_ray,camera_with,shadow_with,"
           "reflection_with,refraction_with,total_with,camera_without,shadow_without,reflection_without,"
           "refraction_without,total_without,mean_abs_diff,max_abs_diff,differing_pixels,load_average\n";

    std::printf("== bench materials: each extension's sample against the same scene without it, %dx%d as `whitted render` "
                "(adaptive anti-aliasing, min weight 1/255); median of %d interleaved run(s), wall clock, %s threads "
                "(load %.2f)\n",
                o.width, o.height, o.repeat, o.threads ? std::to_string(o.threads).c_str() : "all", load_average_1min());
    std::printf("   rays as with/without; kernel: refl/refr = reflection or refraction rays, tex = per-hit attributes, "
                "layers = the layered kernel; |diff| = mean absolute difference of the images (linear)\n");
    std::printf("   %-20s %-22s %5s %-16s %-10s %13s %8s %8s %7s %-5s %7s %19s %17s %17s %9s\n", "extension", "sample", "mats",
                "kernel with", "without", "build w/wo[s]", "with[s]", "w/o[s]", "ratio", "<=1.3", "per ray", "shadow rays",
                "reflection rays", "refraction rays", "|diff|");
    for (const std::string& extension : extensions) {
        // The sample: bundled, or generated into --out.
        const std::optional<fs::path> bundled = o.generated ? std::nullopt : bundled_sample(extension);
        fs::path path;
        ImportOptions io;
        if (bundled) {
            path = *bundled;
        } else {
            path = out / fmt::format("{}.glb", extension);
            (void)write_material_sample(path, extension);
            io.environment = "studio";  // besides its own light, the map a glTF file without lights gets
        }
        const Scene with = load_scene(path.string(), io);
        Scene without = with;
        size_t used = 0;
        for (Material& m : without.materials) {
            used += uses(m, extension) ? 1 : 0;
            remove_extension(m, extension);
        }
        if (used == 0) throw Error(fmt::format("bench materials: {}: no material uses {}", path.string(), extension));

        // Both renderers built once, then the renders interleaved: with, without, with, ...
        Side sides[2];
        sides[0].renderer = std::make_unique<Renderer>(with, bench_settings(with, o));
        sides[1].renderer = std::make_unique<Renderer>(without, bench_settings(without, o));
        for (int run = 0; run < o.repeat; ++run)
            for (Side& s : sides) {
                RenderStats st;
                const Clock::time_point t0 = Clock::now();
                s.film = s.renderer->render(&st);
                s.seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
                s.stats = st;
            }
        const double tw = median(sides[0].seconds), to = median(sides[1].seconds);
        // Each run's pair (with, then without) gives a ratio, and the median of those is the
        // figure: the machine's speed drifts over seconds, which a ratio of two medians would keep.
        std::vector<double> pair_ratios;
        for (size_t k = 0; k < sides[0].seconds.size(); ++k)
            if (sides[1].seconds[k] > 0.0) pair_ratios.push_back(sides[0].seconds[k] / sides[1].seconds[k]);
        const double ratio = pair_ratios.empty() ? 0.0 : median(pair_ratios);
        const Difference d = difference(sides[0].film, sides[1].film);
        const RayCounters& rw = sides[0].stats.rays;
        const RayCounters& ro = sides[1].stats.rays;
        // The ratio at equal work: time per traced ray, with over without (what the extension's
        // evaluation costs, apart from the rays its look adds or removes).
        const double per_ray = rw.total() > 0 && ro.total() > 0 ? ratio * double(ro.total()) / double(rw.total()) : 0.0;
        const KernelFeatures kw = sides[0].renderer->kernel(), ko = sides[1].renderer->kernel();
        const std::string sample = bundled ? path.stem().string() : "generated";
        auto pair = [](uint64_t a, uint64_t b) { return fmt::format("{}/{}", a, b); };
        const double bw = sides[0].renderer->build_seconds(), bo = sides[1].renderer->build_seconds();
        std::printf("   %-20s %-22s %2zu/%-2zu %-16s %-10s %6.3f/%-6.3f %8.4f %8.4f %6.3fx %-5s %6.3fx %19s %17s %17s %9.3g\n",
                    extension.c_str(), sample.c_str(), used, with.materials.size(), short_kernel(kw).c_str(),
                    short_kernel(ko).c_str(), bw, bo, tw, to, ratio, verdict(ratio), per_ray, pair(rw.shadow, ro.shadow).c_str(),
                    pair(rw.reflection, ro.reflection).c_str(), pair(rw.refraction, ro.refraction).c_str(), d.mean_abs);
        std::fflush(stdout);
        csv << fmt::format("{},{},{},{},{},{},{},{},{},{},{},\"{}\",\"{}\",{:.6f},{:.6f},{:.6f},{:.6f},{:.4f},{:.1f},{},{:.4f},{},{},{},{},{},{},{},{},{},{},"
                           "{:.6g},{:.6g},{},{:.2f}\n",
                           extension, material_extension_gltf_name(extension), path.string(), bundled ? 0 : 1, used,
                           with.materials.size(), with.instanced_triangle_count(), o.width, o.height, o.threads, o.repeat,
                           kernel_name(kw), kernel_name(ko), bw, bo, tw, to, ratio, kRatioTarget, verdict(ratio), per_ray, rw.camera,
                           rw.shadow, rw.reflection, rw.refraction, rw.total(), ro.camera, ro.shadow, ro.reflection,
                           ro.refraction, ro.total(), d.mean_abs, d.max_abs, d.pixels, load_average_1min());
        csv.flush();
        // The two images, for the eye.
        write_image(sides[0].film, (out / (extension + ".png")).string(), OutputSettings{});
        write_image(sides[1].film, (out / (extension + "_without.png")).string(), OutputSettings{});
    }
    std::printf("   target: render time with the extension <= %.1fx without it on its sample (a figure, not a check)\n",
                kRatioTarget);
    std::printf("wrote %s and the images <extension>.png, <extension>_without.png\n", (out / "materials.csv").c_str());
    return 0;
}

}  // namespace

Command register_bench_materials(CLI::App& bench) {
    auto o = std::make_shared<BenchMaterialsOptions>();
    CLI::App* app = bench.add_subcommand(
        "materials", "What each glTF material extension costs: its sample rendered with and without it "
                     "(docs/performance.md)");
    app->add_option("--out", o->out, "Output directory: generated samples, materials.csv, images")->capture_default_str();
    app->add_option("--repeat", o->repeat, "Interleaved runs per side (the median is reported)")
        ->check(CLI::Range(1, 100))->capture_default_str();
    app->add_option("--width", o->width, "Render width")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--height", o->height, "Render height")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--threads", o->threads, "Render threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    app->add_option("--only", o->only, "Extensions to measure, comma-separated: " + joined(material_sample_extensions()))
        ->delimiter(',');
    app->add_flag("--generated", o->generated, "Generated samples for clearcoat and anisotropy too (instead of the "
                                               "bundled ClearCoatTest and AnisotropyRotationTest)");
    return Command{app, [o] { return run_bench_materials(*o); }};
}

}  // namespace whitted::app
