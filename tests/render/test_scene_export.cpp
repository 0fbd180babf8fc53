// The scene exporters of `bench process --vs-povray` (benchmarks/scene_export.h): a classic scene
// written as a whitted scene file reads back and renders the same image; written for POV-Ray it
// holds each object once, absolute indices of refraction and the checker's step; what cannot be
// written faithfully is refused with the item named.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <regex>
#include <string>
#include <utility>

#include "benchmarks/scene_export.h"
#include "benchmarks/spd_scenes.h"
#include "core/error.h"
#include "importers/scene_file.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"

namespace whitted {
namespace {

const std::string kWhitted1980 = std::string(WHITTED_SOURCE_DIR) + "/assets/scenes/whitted1980.json";

Film render(const Scene& scene) {
    RenderSettings rs = command_line_render_settings();  // min_weight 1/255, the exporters' default
    apply_scene_settings(scene.settings, rs);
    rs.width = 64;
    rs.height = 48;
    rs.aa.mode = AaMode::Center;
    rs.progress = false;
    return Renderer(scene, rs).render();
}

double max_difference(const Film& a, const Film& b) {
    double worst = 0.0;
    for (size_t i = 0; i < a.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(double(a.beauty[i][c]) - double(b.beauty[i][c])));
    return worst;
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(SceneExport, SceneFileRoundTripRendersTheSameImage) {
    for (const std::string name : {"whitted1980", "rings", "tree", "balls", "tetra", "mount", "gears"}) {
        SCOPED_TRACE(name);
        const Scene original = name == "whitted1980" ? import_scene_file(kWhitted1980) : app::make_spd_scene(name, 1);
        const app::ExportSettings es = app::export_settings(original, 64, 48);
        const std::string text = app::to_scene_file(original, es);
        const Scene back = import_scene_file_text(text, "exported.json");
        EXPECT_EQ(back.spheres.size(), original.spheres.size());
        EXPECT_EQ(back.quadrics.size(), original.quadrics.size());
        EXPECT_EQ(back.instanced_triangle_count(), original.instanced_triangle_count());
        EXPECT_EQ(back.lights.size(), original.lights.size());
        // The settings the original rendered with, written out.
        EXPECT_EQ(back.settings.max_depth.value_or(-1), es.max_depth);
        // Quadrics come back through their matrix (a rounding of the placement at most).
        EXPECT_LT(max_difference(render(original), render(back)), name == "whitted1980" ? 1e-6 : 2e-3);
    }
}

TEST(SceneExport, PovraySceneHoldsEveryObjectOnce) {
    const Scene w = import_scene_file(kWhitted1980);
    const std::string pov = app::to_povray(w, app::export_settings(w, 320, 240));
    EXPECT_EQ(count(pov, "\nsphere {"), w.spheres.size());
    EXPECT_EQ(count(pov, "\nmesh2 {"), w.instances.size());
    EXPECT_NE(pov.find("max_trace_level 9 "), std::string::npos);  // max_depth 8: 9 levels with the camera ray
    EXPECT_NE(pov.find("ambient_light rgb <0.15, 0.15, 0.15>"), std::string::npos);
    // The hollow shell: glass of ior 1.5, the air inside it 1.5 x 0.6666667 = 1 (absolute).
    const std::regex ior(R"(ior ([0-9.e+-]+))");
    std::vector<double> iors;
    for (auto it = std::sregex_iterator(pov.begin(), pov.end(), ior); it != std::sregex_iterator(); ++it)
        iors.push_back(std::stod((*it)[1]));
    ASSERT_EQ(iors.size(), 2u);
    EXPECT_NEAR(iors[0], 1.5, 1e-6);
    EXPECT_NEAR(iors[1], 1.0, 1e-6);
    // The floor's checker moved a step along the floor's normal (whitted's step inside it).
    std::smatch shift;
    const std::regex translate(R"(texture \{ T0 translate <(\S+), (\S+), (\S+)> \})");
    ASSERT_TRUE(std::regex_search(pov, shift, translate)) << pov;
    EXPECT_EQ(std::stod(shift[1]), 0.0);
    EXPECT_NEAR(std::stod(shift[2]), 1e-4 * 0.45, 1e-9);
    EXPECT_EQ(std::stod(shift[3]), 0.0);
    // 16:9 makes the right vector 16/9 long; the vertical field of view 38 degrees.
    const std::string wide = app::to_povray(w, app::export_settings(w, 1920, 1080));
    EXPECT_NE(wide.find("right <1.7777777777777777, "), std::string::npos) << wide;

    const Scene rings = app::make_spd_scene("rings", 1);
    const std::string r = app::to_povray(rings, app::export_settings(rings, 64, 64));
    size_t cylinders = 0, cones = 0, discs = 0;
    for (const Quadric& q : rings.quadrics)
        (q.kind == QuadricKind::Cylinder ? cylinders : q.kind == QuadricKind::Cone ? cones : discs)++;
    EXPECT_EQ(count(r, "\ncylinder {"), cylinders);
    EXPECT_EQ(count(r, "\ncone {"), cones);
    EXPECT_EQ(count(r, "\ndisc {"), discs);
    EXPECT_EQ(count(r, "\nsphere {"), rings.spheres.size());
    EXPECT_EQ(count(r, "fade_power 2"), rings.lights.size());  // inverse-square lights
}

// The SPD-style scenes without quadrics of their own: the counts their size factor gives, and the
// properties that make them the scenes they are named after (closed, crack-free meshes).
TEST(SpdScenes, SphereflakeTetraAndMountainFollowTheSizeFactor) {
    EXPECT_EQ(app::spd_scene_names().size(), 6u);
    for (int size = 1; size <= 2; ++size) {
        SCOPED_TRACE(size);
        // balls: 1 + 9 + ... + 9^size spheres, each child a third of its parent and touching it.
        const Scene balls = app::make_spd_scene("balls", size);
        EXPECT_EQ(balls.spheres.size(), size == 1 ? 10u : 91u);
        const Sphere& root = balls.spheres[0];
        for (size_t k = 1; k <= 9; ++k) {
            const Sphere& child = balls.spheres[size == 1 ? k : 1 + (k - 1) * 10];
            EXPECT_NEAR(child.radius, root.radius / 3.0, 1e-12);
            EXPECT_NEAR(length(child.center - root.center), root.radius + child.radius, 1e-9);
        }
        for (const Sphere& sp : balls.spheres) EXPECT_GT(sp.center.y - sp.radius, 0.0);  // above the ground

        // tetra: 4^(size + 1) tetrahedra of 4 faces, every face of the same area, inside the big one.
        const Scene tetra = app::make_spd_scene("tetra", size);
        ASSERT_EQ(tetra.meshes.size(), 1u);
        const Mesh& t = tetra.meshes[0];
        EXPECT_EQ(t.triangle_count(), size_t(4) << (2 * (size + 1)));
        double area0 = -1.0;
        for (size_t f = 0; f < t.triangle_count(); ++f) {
            const Vec3d a(t.positions[t.indices[3 * f]]), b(t.positions[t.indices[3 * f + 1]]),
                c(t.positions[t.indices[3 * f + 2]]);
            const double area = 0.5 * length(cross(b - a, c - a));
            if (area0 < 0.0) area0 = area;
            EXPECT_NEAR(area, area0, 1e-5 * area0);
            EXPECT_GE(std::min({a.y, b.y, c.y}), 0.0);
        }

        // mount: 4^(size + 3) triangles that share their edges (no crack: each edge inside is met
        // by exactly two triangles at the same two points, each rim edge by one, on the ground),
        // and four spheres above it, one of them glass.
        const Scene mount = app::make_spd_scene("mount", size);
        ASSERT_EQ(mount.meshes.size(), 1u);
        const Mesh& m = mount.meshes[0];
        EXPECT_EQ(m.triangle_count(), size_t(1) << (2 * (size + 3)));
        std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> edges;
        auto key = [](const Vec3f& p) { return std::array<float, 3>{p.x, p.y, p.z}; };
        for (size_t f = 0; f < m.triangle_count(); ++f)
            for (int e = 0; e < 3; ++e) {
                auto p = key(m.positions[m.indices[3 * f + size_t(e)]]), q = key(m.positions[m.indices[3 * f + size_t((e + 1) % 3)]]);
                ++edges[std::minmax(p, q)];
            }
        size_t rim = 0;
        for (const auto& [edge, n] : edges) {
            EXPECT_LE(n, 2);
            if (n == 1) {
                ++rim;
                EXPECT_EQ(edge.first[1], 0.f);
                EXPECT_EQ(edge.second[1], 0.f);
            }
        }
        EXPECT_EQ(rim, size_t(3) << (size + 3));
        float top = 0.f;
        for (const Vec3f& p : m.positions) top = std::max(top, p.y);
        EXPECT_GT(top, 1.0f);  // a mountain, not a plain
        ASSERT_EQ(mount.spheres.size(), 4u);
        int glass = 0;
        for (const Sphere& sp : mount.spheres) glass += !is_black(mount.materials[sp.material].classic.kt);
        EXPECT_EQ(glass, 1);

        // gears: (size + 1)^2 closed gears of 16 teeth (every edge met by exactly two triangles).
        const Scene gears = app::make_spd_scene("gears", size);
        ASSERT_EQ(gears.meshes.size(), 1u);
        const Mesh& g = gears.meshes[0];
        EXPECT_EQ(g.triangle_count(), size_t((size + 1) * (size + 1)) * 16 * 4 * 4);
        std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> gear_edges;
        for (size_t f = 0; f < g.triangle_count(); ++f)
            for (int e = 0; e < 3; ++e)
                ++gear_edges[std::minmax(key(g.positions[g.indices[3 * f + size_t(e)]]),
                                         key(g.positions[g.indices[3 * f + size_t((e + 1) % 3)]]))];
        for (const auto& [edge, n] : gear_edges) EXPECT_EQ(n, 2);
    }
    EXPECT_THROW(app::make_spd_scene("teapot", 1), Error);
}

TEST(SceneExport, RefusesWhatItCannotWriteFaithfully) {
    auto refused = [](const Scene& s, const std::string& what) {
        for (int k = 0; k < 2; ++k) {
            try {
                k == 0 ? (void)app::to_povray(s, app::export_settings(s, 8, 8))
                       : (void)app::to_scene_file(s, app::export_settings(s, 8, 8));
                ADD_FAILURE() << "no error for " << what;
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
            }
        }
    };
    Scene gltf = app::make_spd_scene("rings", 1);
    gltf.materials[0].model = MaterialModel::GltfPbr;
    refused(gltf, "material 'ring' (not a classic material)");
    Scene spot = app::make_spd_scene("rings", 1);
    spot.lights[0].type = LightType::Spot;
    spot.lights[0].name = "key";
    refused(spot, "light 'key' (a spot light)");
    Scene uv = import_scene_file(kWhitted1980);
    for (Texture& t : uv.textures) t.checker.world_space = false;
    refused(uv, "its texture is not a world-space checker");
    Scene none = app::make_spd_scene("tree", 1);
    none.cameras.clear();
    refused(none, "a scene without a camera");
}

}  // namespace
}  // namespace whitted
