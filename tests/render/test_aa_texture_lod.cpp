// Texture MIP selection from the camera's ray cone: a checkerboard far finer than the pixels
// renders as its average (no texture aliasing), while a magnified one keeps its checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/texture_sampling.h"

namespace whitted {
namespace {

/// An unlit quad [-8, 8]^2 with a 256 x 256 checkerboard of `check` x `check` texel squares
/// (black / white, linear data), seen by an orthographic camera over the quad.
Scene checker_scene(int check = 1) {
    Scene s;
    Texture t;
    t.name = "checker";
    MipLevel base;
    base.width = base.height = 256;
    base.texels.resize(256 * 256 * 4);
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x) {
            const uint8_t v = ((x / check + y / check) & 1) ? 255 : 0;
            uint8_t* p = &base.texels[size_t(y * 256 + x) * 4];
            p[0] = p[1] = p[2] = v;
            p[3] = 255;
        }
    t.levels.push_back(std::move(base));
    build_mip_levels(t);
    s.textures.push_back(std::move(t));

    Material m;
    m.unlit = true;
    m.double_sided = true;
    m.base_color_texture.texture = 0;
    s.materials.push_back(m);
    Mesh quad = make_quad({-8, -8, 0}, {8, -8, 0}, {8, 8, 0}, {-8, 8, 0}, 0);
    quad.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    add_mesh(s, std::move(quad));
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, 8.0));
    return s;
}

std::pair<float, float> pixel_range(const Film& film) {
    float lo = 1e9f, hi = -1e9f;
    for (const Color& c : film.beauty) {
        lo = std::min(lo, c.x);
        hi = std::max(hi, c.x);
    }
    return {lo, hi};
}

TEST(AaTextureLod, MinifiedCheckerboardRendersAsItsAverage) {
    const Scene s = checker_scene();
    for (AaMode mode : {AaMode::Center, AaMode::Corners, AaMode::Adaptive}) {
        RenderSettings rs;
        rs.width = rs.height = 16;  // 16 x 16 texels per pixel: MIP level 4
        rs.aa.mode = mode;
        const Film film = Renderer(s, rs).render();
        const auto [lo, hi] = pixel_range(film);
        EXPECT_NEAR(lo, 0.5f, 0.02f) << aa_mode_name(mode);
        EXPECT_NEAR(hi, 0.5f, 0.02f) << aa_mode_name(mode);
    }
}

TEST(AaTextureLod, MagnifiedCheckerboardKeepsItsChecks) {
    const Scene s = checker_scene();
    RenderSettings rs;
    rs.width = rs.height = 1024;  // 4 pixels per texel: level 0
    rs.crop = PixelWindow{0, 0, 64, 64};
    const Film film = Renderer(s, rs).render();
    // Level 0 with the bilinear magnification filter: pixel centres at 1/8, 3/8, 5/8, 7/8 of a
    // texel blend neighbouring checks to 0.21875 .. 0.78125 (a coarser level would give 0.5).
    const auto [lo, hi] = pixel_range(film);
    EXPECT_NEAR(lo, 0.21875f, 1e-4f);
    EXPECT_NEAR(hi, 0.78125f, 1e-4f);
}

TEST(AaTextureLod, TextureFilterNonePointSamplesTheFinestLevel) {
    const Scene s = checker_scene();
    for (AaMode mode : {AaMode::Center, AaMode::Stratified}) {
        RenderSettings rs;
        rs.width = rs.height = 15;  // about 17 texels per pixel, centres at every phase of a check
        rs.aa.mode = mode;
        rs.aa.spp = 1;  // stratified: one jittered point per pixel
        rs.aa.texture_filter = TextureFilter::None;
        const auto [lo, hi] = pixel_range(Renderer(s, rs).render());
        // Point samples of a one-texel checkerboard alias: pixels far from the average of 0.5.
        EXPECT_LT(lo, 0.25f) << aa_mode_name(mode);
        EXPECT_GT(hi, 0.75f) << aa_mode_name(mode);
        rs.aa.texture_filter = TextureFilter::Mip;
        const auto [mip_lo, mip_hi] = pixel_range(Renderer(s, rs).render());
        EXPECT_NEAR(mip_lo, 0.5f, 0.03f) << aa_mode_name(mode);
        EXPECT_NEAR(mip_hi, 0.5f, 0.03f) << aa_mode_name(mode);
    }
}

double rmse(const Film& a, const Film& b) {
    double sum = 0.0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        const double d = double(a.beauty[i].x) - double(b.beauty[i].x);
        sum += d * d;
    }
    return std::sqrt(sum / double(a.beauty.size()));
}

// Requirement of issue 25: the texture footprint follows the sample spacing, so stratified N spp
// with MIP filtering converges to the box-filtered pixel integral of the point-sampled texture
// (here 32 x 32 point samples per pixel). With a pixel-wide footprint for every sample the error
// would stop falling at the blur of a second pixel-wide box: checks of about a pixel make that
// blur large.
TEST(AaTextureLod, StratifiedMipConvergesToThePointSampledPixelIntegral) {
    const Scene s = checker_scene(4);
    RenderSettings rs;
    rs.width = rs.height = 72;  // 3.6 texels per pixel (MIP level 1.8 for a pixel footprint), checks of 1.1 pixels
    rs.aa.mode = AaMode::Stratified;
    rs.aa.spp = 1024;
    rs.aa.texture_filter = TextureFilter::None;
    const Film reference = Renderer(s, rs).render();
    rs.aa.texture_filter = TextureFilter::Mip;
    std::vector<double> error;
    for (int spp : {4, 16, 64, 256}) {
        rs.aa.spp = spp;
        error.push_back(rmse(Renderer(s, rs).render(), reference));
        std::printf("stratified %3d spp, mip: RMSE %.5f against 1024 point samples per pixel\n", spp, error.back());
    }
    for (size_t i = 1; i < error.size(); ++i) EXPECT_LT(error[i], 0.7 * error[i - 1]) << "step " << i;
    EXPECT_LT(error.back(), 0.2 * error.front());
    // Adaptive always-split: the leaves' points get their sub-square's footprint, so a deeper
    // uniform subdivision comes closer as well.
    rs.aa.mode = AaMode::Adaptive;
    rs.aa.threshold = -1.f;
    double previous = 1e9;
    for (int depth : {1, 2, 3}) {
        rs.aa.depth = depth;
        const double e = rmse(Renderer(s, rs).render(), reference);
        std::printf("adaptive always-split depth %d, mip: RMSE %.5f\n", depth, e);
        EXPECT_LT(e, 0.8 * previous) << "depth " << depth;
        previous = e;
    }
}

}  // namespace
}  // namespace whitted
