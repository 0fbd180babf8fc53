// Compressed variants of a model render like the model (issue: compressed glTF). The variants in
// assets/gltf/<Model>/glTF-<Variant>/ are made by scripts/make_compressed_assets.sh (glTF
// Transform). Box's meshopt variant is lossless (floats, no filters): the same image, bit for
// bit. The others are lossy (quantization, WebP): each is held to the PSNR measured for it, with
// a margin (docs/measurements/compressed-gltf.md). Bundled models re-encoded losslessly at test
// time with libmeshoptimizer (tests/support/meshopt_reencode.h, which changes nothing but the
// bufferViews) render bit for bit like their originals. Correctness only: no timings here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "tests/support/meshopt_reencode.h"

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

/// "Duck_glTF_Draco" for "Duck/glTF-Draco/Duck.glb": the test's name.
std::string variant_name(const ::testing::TestParamInfo<Variant>& info) {
    std::string name = std::string(info.param.variant);
    name = name.substr(0, name.rfind('/'));
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

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
                                           Variant{"Box/glTF-Binary/Box.glb", "Box/glTF-Meshopt/Box.glb", INFINITY}),
                         variant_name);

class LosslessMeshopt : public ::testing::TestWithParam<const char*> {};

TEST_P(LosslessMeshopt, RendersBitForBitLikeTheOriginal) {
    const std::string original = kAssets + GetParam();
    const test::MeshoptReencoded encoded = test::meshopt_reencode(test::read_bytes(original));
    EXPECT_GT(encoded.attribute_views, 0);
    EXPECT_GT(encoded.triangle_views + encoded.index_views, 0);
    const std::string path = test::write_file(std::filesystem::path(GetParam()).filename().string(), encoded.glb);
    const Scene scene = load_scene(path);
    ASSERT_FALSE(scene.compressed.empty());
    EXPECT_EQ(scene.compressed.front().codec, "meshopt");
    const Film a = render_file(original), b = render_file(path);
    ASSERT_EQ(a.beauty.size(), b.beauty.size());
    size_t differing = 0;
    for (size_t i = 0; i < a.beauty.size(); ++i)
        differing += std::memcmp(&a.beauty[i], &b.beauty[i], sizeof(a.beauty[i])) != 0;
    std::printf("%s: %d ATTRIBUTES, %d TRIANGLES, %d INDICES views; %zu of %zu pixels differ\n", GetParam(),
                encoded.attribute_views, encoded.triangle_views, encoded.index_views, differing, a.beauty.size());
    EXPECT_EQ(differing, 0u);
}

INSTANTIATE_TEST_SUITE_P(Assets, LosslessMeshopt,
                         ::testing::Values("Duck/glTF-Binary/Duck.glb", "BoxInterleaved/glTF-Binary/BoxInterleaved.glb",
                                           "BoxVertexColors/glTF-Binary/BoxVertexColors.glb",
                                           "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
                                           "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
                                           "GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             return std::filesystem::path(info.param).stem().string();
                         });

}  // namespace
}  // namespace whitted
