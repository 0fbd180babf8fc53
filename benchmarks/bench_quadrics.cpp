// `whitted bench quadrics`: analytic cylinders, cones and discs against the same shapes
// tessellated (docs/performance.md, "whitted bench quadrics").
//
// For each SPD-style scene of --scenes (spd_scenes.h: rings, tree at --size), the analytic scene
// and its tessellations at --segments side quads per cylinder or cone are rendered at --width x
// --height with the default anti-aliasing on --accel. Each is timed --repeat times, interleaved
// (analytic, 8, 16, ..., analytic, 8, ...), as process CPU seconds of building the renderer
// (scene analysis and accelerator) plus rendering, and the median kept. The error of a
// tessellation is its display image's PSNR against the analytic one (which has none: the shapes
// are exact). Prints a table per scene with the time ratio tessellated / analytic, and writes
// <out>/quadrics.csv and the images <out>/<scene>-<mode>.png.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/spd_scenes.h"
#include "core/error.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"
#include "output/image_output.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;

struct BenchQuadricsOptions {
    std::vector<std::string> scenes{"rings", "tree"};
    int size = 2;
    std::vector<int> segments{8, 16, 32, 64};
    int width = 512, height = 512;
    std::string accel = "embree";
    int repeat = 3;
    int threads = 0;
    std::string out = "bench-quadrics";
};

struct Mode {
    std::string label;  ///< "analytic" or "<n> segments"
    Scene scene;
    std::vector<double> seconds;
    Film film;
    RenderStats stats;
    size_t accel_bytes = 0;
};

int run_bench_quadrics(const BenchQuadricsOptions& o) {
    fs::create_directories(o.out);
    std::ofstream csv(fs::path(o.out) / "quadrics.csv");
    csv << "scene,mode,quadrics,triangles,seconds,runs,camera_rays,total_rays,mrays_per_s,accel_bytes,psnr_display,ratio_to_analytic\n";
    const DisplayTransform display(ColorSettings{});
    std::printf("# whitted bench quadrics: %dx%d, %s, median of %d (process CPU s: build + render), load %.1f\n", o.width,
                o.height, o.accel.c_str(), o.repeat, load_average_1min());
    for (const std::string& name : o.scenes) {
        std::vector<Mode> modes;
        modes.push_back({"analytic", make_spd_scene(name, o.size), {}, {}, {}, 0});
        for (const int n : o.segments) modes.push_back({fmt::format("{} segments", n), tessellate_quadrics(modes[0].scene, n), {}, {}, {}, 0});
        for (int run = 0; run < o.repeat; ++run)
            for (Mode& m : modes) {
                RenderSettings rs = command_line_render_settings();
                apply_scene_settings(m.scene.settings, rs);
                rs.width = o.width;
                rs.height = o.height;
                rs.accel = o.accel;
                rs.threads = o.threads;
                rs.progress = false;
                const double t0 = process_cpu_seconds();
                Renderer renderer(m.scene, rs);
                RenderStats st;
                Film film = renderer.render(&st);
                m.seconds.push_back(process_cpu_seconds() - t0);
                if (run == 0) {
                    m.film = std::move(film);
                    m.stats = st;
                    m.accel_bytes = renderer.accelerator().stats().bytes;
                }
            }
        const std::vector<float> reference = display_rgb(packed_rgb(modes[0].film), display);
        const double analytic_s = median(modes[0].seconds);
        std::printf("\n== %s (size %d): %zu quadrics, %zu spheres\n", name.c_str(), o.size, modes[0].scene.quadrics.size(),
                    modes[0].scene.spheres.size());
        std::printf("  %-12s %10s %9s %9s %10s %9s %10s %9s\n", "mode", "triangles", "seconds", "x analytic", "Mrays/s",
                    "accel MiB", "PSNR dB", "rays (M)");
        for (Mode& m : modes) {
            const double s = median(m.seconds);
            const std::vector<float> img = display_rgb(packed_rgb(m.film), display);
            const double e = rmse(img, reference);
            const double psnr = e > 0.0 ? 20.0 * std::log10(1.0 / e) : kInfinity;
            const double mrays = double(m.stats.rays.total()) / std::max(1e-9, m.stats.render_seconds) * 1e-6;
            const double ratio = s / analytic_s;
            std::printf("  %-12s %10zu %9.3f %9.2f %10.2f %9.1f %10.2f %9.2f\n", m.label.c_str(), m.scene.instanced_triangle_count(),
                        s, ratio, mrays, double(m.accel_bytes) / double(1 << 20), psnr, double(m.stats.rays.total()) * 1e-6);
            csv << fmt::format("{},{},{},{},{:.6f},{},{},{},{:.4f},{},{:.3f},{:.4f}\n", name, m.label, m.scene.quadrics.size(),
                               m.scene.instanced_triangle_count(), s, m.seconds.size(), m.stats.rays.camera,
                               m.stats.rays.total(), mrays, m.accel_bytes, psnr, ratio);
            std::string file = m.label;
            std::replace(file.begin(), file.end(), ' ', '-');
            write_image(m.film, (fs::path(o.out) / fmt::format("{}-{}.png", name, file)).string(), OutputSettings{});
        }
    }
    std::printf("\nwrote %s\n", (fs::path(o.out) / "quadrics.csv").c_str());
    return 0;
}

}  // namespace

Command register_bench_quadrics(CLI::App& bench) {
    auto o = std::make_shared<BenchQuadricsOptions>();
    CLI::App* app = bench.add_subcommand(
        "quadrics", "Analytic cylinders, cones and discs against the same shapes tessellated: time and image error on "
                    "SPD-style scenes (docs/performance.md)");
    app->add_option("--scenes", o->scenes, "Scenes, comma-separated: rings, tree")->delimiter(',')->capture_default_str();
    app->add_option("--size", o->size, "SPD size factor (rings: pyramid levels - 1; tree: depth - 4)")
        ->check(CLI::Range(1, 6))->capture_default_str();
    app->add_option("--segments", o->segments, "Tessellations compared: side quads per cylinder or cone, comma-separated")
        ->delimiter(',')->check(CLI::Range(3, 4096))->capture_default_str();
    app->add_option("--width", o->width, "Image width")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--height", o->height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--accel", o->accel, "Accelerator")->capture_default_str();
    app->add_option("--repeat", o->repeat, "Timed runs per mode (median kept)")->check(CLI::Range(1, 100))->capture_default_str();
    app->add_option("--threads", o->threads, "Render threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--out", o->out, "Output directory: quadrics.csv and the images")->capture_default_str();
    return Command{app, [o] { return run_bench_quadrics(*o); }};
}

}  // namespace whitted::app
