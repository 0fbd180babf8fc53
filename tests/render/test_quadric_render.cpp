// Analytic quadrics rendered: an SPD-style scene of cylinders, cones and discs (benchmarks/
// spd_scenes.h) against the same shapes finely tessellated with smooth normals. The images must
// agree closely (same shading normals, UVs, shadows and reflections, up to the silhouette of a
// 512-gon), and a coarse tessellation must not (the comparison can fail).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "benchmarks/spd_scenes.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"

namespace whitted {
namespace {

Film render(const Scene& scene, const std::string& accel) {
    RenderSettings rs;
    apply_scene_settings(scene.settings, rs);
    rs.width = 96;
    rs.height = 96;
    rs.accel = accel;
    rs.progress = false;
    return Renderer(scene, rs).render();
}

/// Mean absolute difference over channels and the fraction of pixels off by more than 0.05.
std::pair<double, double> difference(const Film& a, const Film& b) {
    double sum = 0.0;
    size_t off = 0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double d = std::fabs(double(a.beauty[i][c]) - double(b.beauty[i][c]));
            sum += d;
            worst = std::max(worst, d);
        }
        off += worst > 0.05;
    }
    return {sum / double(3 * a.beauty.size()), double(off) / double(a.beauty.size())};
}

TEST(QuadricRender, AnalyticMatchesAFineTessellation) {
    for (const char* name : {"rings", "tree"}) {
        SCOPED_TRACE(name);
        const Scene analytic = app::make_spd_scene(name, 1);
        ASSERT_FALSE(analytic.quadrics.empty());
        const Film exact = render(analytic, "embree");
        const auto [fine_mean, fine_off] = difference(exact, render(app::tessellate_quadrics(analytic, 512), "embree"));
        const auto [coarse_mean, coarse_off] = difference(exact, render(app::tessellate_quadrics(analytic, 6), "embree"));
        std::printf("[ quadric render ] %s: 512-gon mean |diff| %.5f, %.4f of pixels > 0.05; 6-gon %.5f, %.4f\n", name,
                    fine_mean, fine_off, coarse_mean, coarse_off);
        EXPECT_LT(fine_mean, 0.001);
        EXPECT_LT(fine_off, 0.003);
        EXPECT_GT(coarse_off, 2.0 * fine_off + 0.005);  // the comparison sees a coarse tessellation
        // The in-house BVH draws the analytic scene as Embree does.
        const auto [bvh_mean, bvh_off] = difference(exact, render(analytic, "bvh"));
        EXPECT_LT(bvh_mean, 1e-5);
        EXPECT_EQ(bvh_off, 0.0);
    }
}

}  // namespace
}  // namespace whitted
