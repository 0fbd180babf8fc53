// Google Benchmark: build and closest-hit traversal of every accelerator on a 100k-triangle
// random soup (quick per-commit figures; `whitted bench accel` is the full study with scaling,
// validation and plots, see docs/accelerators.md).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "accel/accelerator.h"
#include "accel/factory/create_accelerator.h"
#include "scene/scene.h"

namespace {

using namespace whitted;

class Opaque final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }
    uint32_t mesh_flags(uint32_t) const override { return 0; }
};

const Scene& soup() {
    static const Scene scene = [] {
        Scene s;
        Mesh m;
        std::mt19937 rng(1);
        std::uniform_real_distribution<float> p(-1.f, 1.f), o(-0.03f, 0.03f);
        for (int i = 0; i < 100000; ++i) {
            const Vec3f c{p(rng), p(rng), p(rng)};
            for (int k = 0; k < 3; ++k) {
                m.positions.push_back(c + Vec3f(o(rng), o(rng), o(rng)));
                m.indices.push_back(uint32_t(m.positions.size() - 1));
            }
        }
        s.meshes.push_back(std::move(m));
        s.instances.push_back(Instance{});
        return s;
    }();
    return scene;
}

std::vector<Ray> random_rays(size_t n) {
    std::mt19937 rng(2);
    std::normal_distribution<float> g;
    std::vector<Ray> rays(n);
    for (Ray& r : rays) {
        r.org = Vec3f(g(rng), g(rng), g(rng)) * 0.3f;
        r.dir = Vec3f(g(rng), g(rng), g(rng));
    }
    return rays;
}

// "bvh" is the 8-wide BVH; "bvh:width=2" the binary tree it is collapsed from.
const char* const kNames[] = {"embree", "bvh", "bvh:width=4", "bvh:width=2", "bvh:bv=sphere", "kdop", "grid", "octree"};
constexpr int kLastName = int(sizeof(kNames) / sizeof(kNames[0])) - 1;

void BM_Build(benchmark::State& state) {
    Opaque filter;
    for (auto _ : state) benchmark::DoNotOptimize(create_accelerator(kNames[state.range(0)], soup(), filter));
    state.SetLabel(kNames[state.range(0)]);
}

void BM_Intersect(benchmark::State& state) {
    Opaque filter;
    const auto accel = create_accelerator(kNames[state.range(0)], soup(), filter);
    const std::vector<Ray> rays = random_rays(4096);
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(accel->intersect(rays[i], RayKind::Reflection));
        i = (i + 1) & 4095;
    }
    state.SetItemsProcessed(int64_t(state.iterations()));
    state.SetLabel(kNames[state.range(0)]);
}

BENCHMARK(BM_Build)->DenseRange(0, kLastName)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Intersect)->DenseRange(0, kLastName);

}  // namespace

BENCHMARK_MAIN();
