// Deep ray trees (docs/numerical-stability.md, section 5). Two parallel mirrors with max depth
// 1 ... 200: the render terminates, does not overflow the stack (also on TBB worker threads) and
// the radiance is the geometric series a (1 - r^(D+1)) / (1 - r) Whitted's recursion predicts.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "benchmarks/stability_probes.h"
#include "core/error.h"
#include "scene/scene_builder.h"

namespace whitted::stress {
namespace {

/// Mirrors z = 0 (facing +z) and z = d (facing -z), ka = 0.5, kr = r, nothing else; ambient 0.2,
/// so every bounce adds a = 0.1 and the pixel after max depth D is a sum_{k=0..D} r^k.
Scene mirrors(double d, float r, bool analytic) {
    Scene s;
    WhittedCoeffs c;
    c.ka = Color(0.5f);
    c.kr = Color(r);
    const uint32_t m = add_classic_material(s, c, "mirror");
    if (analytic) {
        Plane a, b;
        a.point = {0, 0, 0};
        a.normal = {0, 0, 1};
        b.point = {0, 0, d};
        b.normal = {0, 0, -1};
        a.material = b.material = m;
        s.planes = {a, b};
    } else {
        const float h = 10.f, z = float(d);
        add_mesh(s, make_quad({-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}, m));
        add_mesh(s, make_quad({-h, -h, z}, {-h, h, z}, {h, h, z}, {h, -h, z}, m));
    }
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0.1, 0.2, 0.5 * d}, {0, 0, -1}, {0, 1, 0}, 0.01));
    return s;
}

TEST(StressDeepTree, ParallelMirrorsFollowTheGeometricSeries) {
    const float r = 0.9f;
    const double a = 0.1;
    for (bool analytic : {true, false})
        for (const char* accel : {"bvh", "embree"})
            for (int depth : {1, 2, 5, 10, 50, 100, 200})
                for (int threads : {1, 2}) {
                    const Scene s = mirrors(1.0, r, analytic);
                    RenderSettings rs;
                    rs.width = rs.height = 2;
                    rs.threads = threads;
                    rs.tile_size = 1;
                    rs.accel = accel;
                    rs.integrator.max_depth = depth;
                    rs.integrator.ambient = Color(0.2f);
                    RenderStats stats;
                    const Film f = Renderer(s, rs).render(&stats);
                    const double want = a * (1.0 - std::pow(double(r), depth + 1)) / (1.0 - double(r));
                    const std::string what = std::string(accel) + (analytic ? " planes" : " quads") + " depth " +
                                             std::to_string(depth) + " threads " + std::to_string(threads);
                    for (const Color& c : f.beauty) EXPECT_NEAR(double(c.x), want, 2e-6 * (depth + 1)) << what;
                    // Every level traced: 4 camera rays, 4 * depth reflections, no escapes.
                    EXPECT_EQ(stats.rays.reflection, uint64_t(4 * depth)) << what;
                    EXPECT_EQ(stats.nonfinite_samples, 0u) << what;
                }
}

// Hall & Greenberg's adaptive depth stops the same tree once the path weight r^k falls below
// min_weight: k = ceil(log(w) / log(r)) levels, whatever max depth allows.
TEST(StressDeepTree, MinWeightCutsTheTree) {
    const float r = 0.9f;
    const Scene s = mirrors(1.0, r, true);
    RenderSettings rs;
    rs.width = rs.height = 1;
    rs.threads = 1;
    rs.integrator.max_depth = 200;
    rs.integrator.ambient = Color(0.2f);
    rs.integrator.min_weight = 1.f / 255.f;
    RenderStats stats;
    const Film f = Renderer(s, rs).render(&stats);
    // r^k >= 1/255 for k <= 52 (0.9^52 = 0.00416, 0.9^53 = 0.00374).
    EXPECT_EQ(stats.rays.reflection, 52u);
    EXPECT_NEAR(double(f.beauty[0].x), 0.1 * (1.0 - std::pow(0.9, 53)) / 0.1, 1e-4);
}

// The ray tree recurses on the thread's stack (a few hundred bytes per level), so the Renderer
// refuses a max_depth above kMaxTreeDepth instead of overflowing it.
TEST(StressDeepTree, RendererRejectsDepthBeyondTheStack) {
    RenderSettings rs;
    rs.width = rs.height = 1;
    rs.integrator.max_depth = 1 << 20;
    const Scene s = mirrors(1.0, 0.9f, true);
    EXPECT_THROW(Renderer(s, rs), Error);
    rs.integrator.max_depth = kMaxTreeDepth + 1;
    EXPECT_THROW(Renderer(s, rs), Error);
    rs.integrator.max_depth = kMaxTreeDepth;  // the deepest accepted tree renders
    EXPECT_NO_THROW(Renderer(s, rs).render());
}

}  // namespace
}  // namespace whitted::stress
