// The layered material extensions in whole renders: analytic pixels for the coat and diffuse
// transmission, the per-channel refracted rays of dispersion, determinism across threads and
// tiles (the dispersion channel is carried per thread), and the kernel each scene selects.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted {
namespace {

uint32_t add_material(Scene& s, const Material& m) {
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

Material gltf_dielectric(Color base, float roughness) {
    Material m;
    m.base_color = {base.x, base.y, base.z, 1.f};
    m.metallic = 0.f;
    m.roughness = roughness;
    m.double_sided = true;
    return m;
}

RenderSettings one_pixel() {
    RenderSettings rs;
    rs.width = rs.height = 1;
    rs.threads = 1;
    rs.integrator.ambient = Color(0.1f);
    rs.aa.mode = AaMode::Center;
    return rs;
}

Color render_pixel(const Scene& s, RenderSettings rs = one_pixel(), RenderStats* stats = nullptr) {
    Renderer r(s, rs);
    const Film film = r.render(stats);
    return film.beauty[film.index(0, 0)];
}

void expect_near(const Color& a, const Color& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

/// A quad at z = 0 facing +z, seen straight on by an orthographic camera at +z.
Scene facing_quad(const Material& m) {
    Scene s;
    add_mesh(s, make_quad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, add_material(s, m)));
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, 0.5));
    return s;
}

TEST(LayeredRender, ClearcoatOnBlackIsItsFresnelTimesTheLight) {
    // Black base, smooth coat, a directional light along the view: H = N, so the coat's highlight
    // is 1 and its weight at normal incidence is 0.04 (KHR_materials_clearcoat's F0).
    Material m = gltf_dielectric(Color(0.f), 1.f);
    m.specular = 0.f;  // no base highlight
    m.clearcoat = 1.f;
    m.clearcoat_roughness = 0.f;
    Scene s = facing_quad(m);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = {0, 0, -1};
    sun.intensity = 5.f;
    sun.attenuation = Attenuation::None;
    s.lights.push_back(sun);
    RenderStats stats;
    expect_near(render_pixel(s, one_pixel(), &stats), Color(0.04f * 5.f), 1e-5f);
    EXPECT_EQ(stats.rays.reflection, 1u);  // the coat's mirror ray (to the black background)
}

TEST(LayeredRender, ASmoothCoatOverASmoothBaseIsOneMirrorRay) {
    // Coat and base share their normal (no normal maps) and both are mirrors: one reflected ray
    // carries kr (1 - w) + w. A white background makes it the sum of the two weights.
    Material m = gltf_dielectric(Color(0.f), 0.f);
    m.metallic = 1.f;
    m.base_color = {0.5f, 0.5f, 0.5f, 1.f};
    m.clearcoat = 1.f;
    m.clearcoat_roughness = 0.f;
    RenderSettings rs = one_pixel();
    rs.integrator.background = Color(1.f);
    rs.integrator.ambient = Color(0.f);
    RenderStats stats;
    const Color I = render_pixel(facing_quad(m), rs, &stats);
    EXPECT_EQ(stats.rays.reflection, 1u);
    // Base kr = F0 = 0.5 at roughness 0; the coat's weight 0.04 at normal incidence.
    expect_near(I, Color(0.5f * (1.f - 0.04f) + 0.04f), 1e-5f);
    // Without the coat: the base's mirror alone.
    m.clearcoat = 0.f;
    expect_near(render_pixel(facing_quad(m), rs), Color(0.5f), 1e-6f);
}

TEST(LayeredRender, DiffuseTransmissionLetsLightThroughFromBehind) {
    // A white diffuse sheet with diffuse transmission 1, lit only from behind by a point light at
    // distance 2 of intensity 8: I = kdt (Is / d^2) |N.L| + Ia kdt, kdt = colour x 0.96.
    Material m = gltf_dielectric(Color(1.f), 1.f);
    m.diffuse_transmission = 1.f;
    m.diffuse_transmission_color = {1.f, 0.5f, 0.25f};
    Scene s = facing_quad(m);
    s.lights.push_back(point_light({0, 0, -2}, 8.f));
    const Color kdt = Color(1.f, 0.5f, 0.25f) * 0.96f;
    RenderStats stats;
    expect_near(render_pixel(s, one_pixel(), &stats), kdt * (8.f / 4.f) + kdt * 0.1f, 1e-5f);
    EXPECT_EQ(stats.rays.shadow, 1u);  // from the back side, unblocked
    // Without the extension the sheet is dark from the front: the light is behind it.
    m.diffuse_transmission = 0.f;
    expect_near(render_pixel(facing_quad(m)), Color(0.96f * 0.1f), 1e-5f);
}

/// A glass block (KHR_materials_volume) in front of a white/black striped wall, seen at an angle.
Scene glass_block(float dispersion) {
    Scene s;
    Material glass = gltf_dielectric(Color(1.f), 0.f);
    glass.transmission = 1.f;
    glass.has_volume = true;
    glass.thickness = 1.f;
    glass.ior = 1.5f;
    glass.dispersion = dispersion;
    const uint32_t g = add_material(s, glass);
    add_mesh(s, make_box({-1, -1, -1}, {1, 1, 1}, g), Mat4d::rotate(0.14, 0.3, 0.0, std::sqrt(1.0 - 0.14 * 0.14 - 0.3 * 0.3)));
    WhittedCoeffs white, black;
    white.kd = white.ka = Color(1.f);
    black.kd = black.ka = Color(0.02f);
    const uint32_t w = add_classic_material(s, white), b = add_classic_material(s, black);
    for (int i = -6; i < 6; ++i)
        add_mesh(s, make_quad({float(i), -6, -3}, {float(i) + 1, -6, -3}, {float(i) + 1, 6, -3}, {float(i), 6, -3},
                              (i & 1) ? w : b));
    s.lights.push_back(point_light({0, 0, 6}, 40.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0, 6}, {0, 0, -1}, {0, 1, 0}, 0.6));
    return s;
}

RenderSettings small(int threads, int tile) {
    RenderSettings rs;
    rs.width = 64;
    rs.height = 48;
    rs.threads = threads;
    rs.tile_size = tile;
    rs.integrator.min_weight = 0.f;
    rs.aa.mode = AaMode::Corners;
    return rs;
}

TEST(LayeredRender, DispersionTracesOneRefractedRayPerChannel) {
    RenderStats plain, dispersed;
    const Film a = Renderer(glass_block(0.f), small(1, 16)).render(&plain);
    const Film b = Renderer(glass_block(2.f), small(1, 16)).render(&dispersed);
    // Dispersion 0 is one ray (and not even the layered kernel); > 0 splits at the first surface
    // and keeps each channel's ray single after that.
    ASSERT_GT(plain.rays.refraction, 500u);
    EXPECT_GT(dispersed.rays.refraction, 2 * plain.rays.refraction);
    EXPECT_LE(dispersed.rays.refraction, 3 * plain.rays.refraction);
    // White light through the block over a grey-free wall: dispersion colours the edges.
    double colour_a = 0, colour_b = 0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        colour_a += std::abs(a.beauty[i].x - a.beauty[i].z);
        colour_b += std::abs(b.beauty[i].x - b.beauty[i].z);
    }
    EXPECT_LT(colour_a, 1e-4 * double(a.beauty.size()));
    EXPECT_GT(colour_b, 100.0 * colour_a + 1.0);  // summed |R - B| over the image
}

TEST(LayeredRender, ThreadsAndTilesDoNotChangeALayeredImage) {
    Scene s = glass_block(2.f);
    // A coat and sheen on the wall's neighbour, so the layered kernel also shades lights.
    Material velvet = gltf_dielectric({0.3f, 0.1f, 0.1f}, 0.8f);
    velvet.sheen_color = {0.9f, 0.9f, 0.9f};
    velvet.sheen_roughness = 0.4f;
    velvet.clearcoat = 0.7f;
    add_mesh(s, make_quad({-6, -3, -2.9f}, {6, -3, -2.9f}, {6, -2, -2.9f}, {-6, -2, -2.9f}, add_material(s, velvet)));
    const Film reference = Renderer(s, small(1, 16)).render();
    for (auto [threads, tile] : {std::pair{4, 7}, std::pair{3, 64}, std::pair{8, 1}}) {
        const Film f = Renderer(s, small(threads, tile)).render();
        ASSERT_EQ(f.beauty.size(), reference.beauty.size());
        EXPECT_EQ(std::memcmp(f.beauty.data(), reference.beauty.data(), f.beauty.size() * sizeof(Color)), 0)
            << threads << " threads, tile " << tile;
    }
}

TEST(LayeredRender, AVelvetSceneRunsTheLayeredKernelWithoutMirrorsAndMatchesTheGeneralOne) {
    // Sheen on a rough base casts no mirror ray: the smallest layered kernel, the same bits as the
    // general kernel (which has every feature).
    Scene s;
    Material velvet = gltf_dielectric({0.2f, 0.1f, 0.3f}, 0.9f);
    velvet.sheen_color = {1.f, 0.8f, 0.9f};
    velvet.sheen_roughness = 0.5f;
    add_mesh(s, make_box({-1, -1, -1}, {1, 1, 1}, add_material(s, velvet)), Mat4d::rotate(0.2, 0.3, 0.1, std::sqrt(1.0 - 0.14)));
    add_mesh(s, make_quad({-6, -6, -1.5f}, {6, -6, -1.5f}, {6, 6, -1.5f}, {-6, 6, -1.5f}, add_material(s, gltf_dielectric(Color(0.7f), 1.f))));
    s.lights.push_back(point_light({2, 3, 6}, 40.f));
    s.lights.push_back(point_light({-4, 1, 2}, 10.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0, 6}, {0, 0, -1}, {0, 1, 0}, 0.7));
    RenderSettings rs = small(2, 16);
    const Renderer special(s, rs);
    EXPECT_TRUE(special.kernel().layers);
    EXPECT_FALSE(special.kernel().mirror);
    rs.integrator.specialize = false;
    const Film a = special.render();
    const Film b = Renderer(s, rs).render();
    ASSERT_EQ(a.beauty.size(), b.beauty.size());
    EXPECT_EQ(std::memcmp(a.beauty.data(), b.beauty.data(), a.beauty.size() * sizeof(Color)), 0);
}

TEST(LayeredRender, OnlyScenesWithALayerRunTheLayeredKernel) {
    EXPECT_TRUE(Renderer(glass_block(1.f), small(1, 16)).kernel().layers);
    EXPECT_FALSE(Renderer(glass_block(0.f), small(1, 16)).kernel().layers);
}

}  // namespace
}  // namespace whitted
