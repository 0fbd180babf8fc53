// Texture MIP selection from the camera's ray cone: a checkerboard far finer than the pixels
// renders as its average (no texture aliasing), while a magnified one keeps its checks.
#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/integrator/render.h"
#include "renderer/scene/scene_builder.h"
#include "shading/texture_sampling.h"

namespace whitted {
namespace {

/// An unlit quad [-8, 8]^2 with a 256 x 256 one-texel checkerboard (black / white, linear data),
/// seen by an orthographic camera of `size` pixels over the quad.
Scene checker_scene() {
    Scene s;
    Texture t;
    t.name = "checker";
    MipLevel base;
    base.width = base.height = 256;
    base.texels.resize(256 * 256 * 4);
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x) {
            const uint8_t v = ((x + y) & 1) ? 255 : 0;
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

}  // namespace
}  // namespace whitted
