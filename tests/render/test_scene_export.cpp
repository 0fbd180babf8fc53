// The scene exporters of `bench process --vs-povray` (benchmarks/scene_export.h): a classic scene
// written as a whitted scene file reads back and renders the same image; written for POV-Ray it
// holds each object once, absolute indices of refraction and the checker's step; what cannot be
// written faithfully is refused with the item named.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

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
    for (const std::string name : {"whitted1980", "rings", "tree"}) {
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
