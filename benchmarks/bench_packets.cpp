// Google Benchmark: the Embree backend's single-ray closest-hit query against its batch query
// (packets of 4, 8 or 16 rays) on coherent camera rays, with the renderer's own SurfaceFilter
// (SceneView: alpha cut-outs, back-face culling of single-sided materials). Rays are the scene
// camera's pixel centres at 640 pixels wide, in 32x32 tiles, each tile row by row; a batch is one
// tile row of 32 rays, as the renderer would trace them. Rates are rays per CPU second
// ("items_per_second"). Before timing, every batch answer is checked against the single-ray one
// (same primitive or the same t within 1e-6: tests/accel/test_accel_queries.cpp has the rule).
//
//   build/benchmarks/bench_packets --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "importers/scene_loader.h"
#include "accel/accelerator.h"
#include "accel/factory/create_accelerator.h"
#include "integrator/camera.h"
#include "integrator/scene_view.h"

namespace {

using namespace whitted;

constexpr int kTile = 32;

struct Setup {
    Scene scene;
    std::unique_ptr<SceneView> view;
    std::vector<Ray> rays;  ///< tile by tile, row by row inside a tile (rows of up to kTile rays)
    std::vector<size_t> rows;  ///< start of each tile row in `rays`, plus rays.size()
};

const char* const kScenes[] = {"/scenes/default.glb", "/gltf/Duck/glTF-Binary/Duck.glb"};
const char* const kSceneNames[] = {"default.glb", "Duck"};

const Setup& setup(int index) {
    static std::unique_ptr<Setup> cache[2];
    if (cache[index]) return *cache[index];
    auto s = std::make_unique<Setup>();
    s->scene = load_scene(std::string(WHITTED_ASSETS_DIR) + kScenes[index]);
    s->view = std::make_unique<SceneView>(s->scene, MappingOptions{});
    const Camera& cam = s->scene.cameras.at(size_t(s->scene.settings.camera.value_or(0)));
    const ImageSize size = resolve_image_size(cam, 640, 0);
    const CameraModel camera(cam, size.width, size.height);
    for (int ty = 0; ty < size.height; ty += kTile)
        for (int tx = 0; tx < size.width; tx += kTile)
            for (int y = ty; y < std::min(ty + kTile, size.height); ++y) {
                s->rows.push_back(s->rays.size());
                for (int x = tx; x < std::min(tx + kTile, size.width); ++x)
                    s->rays.push_back(camera.generate(double(x) + 0.5, double(y) + 0.5));
            }
    s->rows.push_back(s->rays.size());
    cache[index] = std::move(s);
    return *cache[index];
}

/// Fraction of rays whose batch answer is neither the single-ray one nor a tie at equal t.
double disagreement(const Accelerator& accel, const Setup& s) {
    std::vector<Hit> hits(s.rays.size());
    for (size_t r = 0; r + 1 < s.rows.size(); ++r) {
        const size_t b = s.rows[r], n = s.rows[r + 1] - b;
        accel.intersect(std::span<const Ray>(s.rays.data() + b, n), RayKind::Camera, std::span<Hit>(hits.data() + b, n));
    }
    size_t bad = 0;
    for (size_t i = 0; i < s.rays.size(); ++i) {
        const Hit a = accel.intersect(s.rays[i], RayKind::Camera), &b = hits[i];
        if (a.valid() != b.valid()) ++bad;
        else if (a.valid() && std::fabs(a.t - b.t) > 1e-6f * std::max(a.t, b.t)) ++bad;
    }
    return double(bad) / double(s.rays.size());
}

/// range(0): scene; range(1): 0 = single-ray intersect() per ray, else the batch query with
/// Embree packets of that width.
void BM_CameraRays(benchmark::State& state) {
    const Setup& s = setup(int(state.range(0)));
    const int width = int(state.range(1));
    const std::string name = width == 0 ? "embree" : "embree:packet=" + std::to_string(width);
    AccelConfig config;
    config.threads = 1;
    const auto accel = create_accelerator(name, s.scene, *s.view, config);
    if (width > 0) {
        const double bad = disagreement(*accel, s);
        if (bad > 1e-3) state.SkipWithError(("batch answers differ on " + std::to_string(bad * 100) + "% of rays").c_str());
    }
    std::vector<Hit> hits(kTile);
    for (auto _ : state) {
        if (width == 0) {
            for (const Ray& r : s.rays) benchmark::DoNotOptimize(accel->intersect(r, RayKind::Camera));
        } else {
            for (size_t r = 0; r + 1 < s.rows.size(); ++r) {
                const size_t b = s.rows[r], n = s.rows[r + 1] - b;
                accel->intersect(std::span<const Ray>(s.rays.data() + b, n), RayKind::Camera,
                                 std::span<Hit>(hits.data(), n));
                benchmark::DoNotOptimize(hits.data());
            }
        }
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(s.rays.size()));
    state.SetLabel(std::string(kSceneNames[state.range(0)]) + (width == 0 ? " single" : " batch" + std::to_string(width)));
}

BENCHMARK(BM_CameraRays)->ArgsProduct({{0, 1}, {0, 4, 8, 16}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
