// Compressed variants of a model render like the model (issue: compressed glTF). The variants in
// assets/gltf/<Model>/glTF-<Variant>/ are made by scripts/make_compressed_assets.sh (glTF
// Transform). Box's meshopt variant is lossless (floats, no filters): the same image, bit for
// bit. The others are lossy (quantization, WebP): each is held to the PSNR measured for it, with
// a margin (docs/measurements/compressed-gltf.md). Correctness only: no timings here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "importers/scene_loader.h"
#include "renderer/integrator/render.h"
#include "renderer/scene/scene_builder.h"

namespace whitted {
namespace {

const std::string kAssets = std::string(WHITTED_ASSETS_DIR) + "/gltf/";

Film render_file(const std::string& path) {
    const Scene scene = load_scene(path);
    RenderSettings rs;
    apply_scene_settings(scene.settings, rs);
    rs.width = 160;
    rs.height = 160;
    const Renderer renderer(scene, rs);
    return renderer.render();
}

/// PSNR of the beauty, each channel clamped to [0, 1] (peak 1); +inf when identical.
double psnr(const Film& a, const Film& b) {
    EXPECT_EQ(a.beauty.size(), b.beauty.size());
    double se = 0;
    for (size_t i = 0; i < a.beauty.size() && i < b.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = std::clamp(double(a.beauty[i][c]), 0.0, 1.0) - std::clamp(double(b.beauty[i][c]), 0.0, 1.0);
            se += d * d;
        }
    const double mse = se / double(3 * a.beauty.size());
    return mse == 0 ? INFINITY : 10 * std::log10(1 / mse);
}

struct Variant {
    const char* original;
    const char* variant;
    double min_psnr;  ///< measured value minus a margin; INFINITY: bit-identical (lossless meshopt)
};

class CompressedVariant : public ::testing::TestWithParam<Variant> {};

TEST_P(CompressedVariant, RendersLikeTheOriginal) {
    const Variant& v = GetParam();
    const Film original = render_file(kAssets + v.original);
    const Film variant = render_file(kAssets + v.variant);
    const double db = psnr(original, variant);
    std::printf("%s: PSNR %.2f dB against %s\n", v.variant, db, v.original);
    EXPECT_GE(db, v.min_psnr);
}

INSTANTIATE_TEST_SUITE_P(Assets, CompressedVariant,
                         ::testing::Values(Variant{"Duck/glTF-Binary/Duck.glb", "Duck/glTF-Draco/Duck.glb", 75},
                                           Variant{"Duck/glTF-Binary/Duck.glb", "Duck/glTF-MeshoptFiltered/Duck.glb", 66},
                                           Variant{"Duck/glTF-Binary/Duck.glb", "Duck/glTF-WebP/Duck.glb", 62},
                                           Variant{"Box/glTF-Binary/Box.glb", "Box/glTF-Draco/Box.glb", 90},
                                           Variant{"Box/glTF-Binary/Box.glb", "Box/glTF-Meshopt/Box.glb", INFINITY}));

}  // namespace
}  // namespace whitted
