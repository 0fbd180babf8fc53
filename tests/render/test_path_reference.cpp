// The path-traced reference of `whitted bench env --path-reference` (benchmarks/path_reference.h):
// cases with exact answers (a white mirror under a uniform map is the map; nothing arrives inside
// a closed box), a diffuse furnace against the glTF BRDF's albedo bounds, determinism across
// thread counts, and what it refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "benchmarks/path_reference.h"
#include "core/error.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "tests/support/environment_scenes.h"

namespace whitted {
namespace {

using app::path_trace;
using app::PathSettings;

uint32_t add_pbr(Scene& s, Color base, float metallic, float roughness) {
    Material m;
    m.name = "pbr";
    m.base_color = Vec4f(base.x, base.y, base.z, 1.f);
    m.metallic = metallic;
    m.roughness = roughness;
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

/// A sphere of radius 1 at the origin seen from z = 4 under a uniform map of `L`.
Scene lone_sphere(uint32_t (*material)(Scene&), Color L) {
    Scene s;
    Sphere sp;
    sp.radius = 1.0;
    sp.material = material(s);
    s.spheres.push_back(sp);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0, 4}, {0, 0, -1}, {0, 1, 0}, 0.6));
    test::light_with(s, test::constant_environment(L), 0);
    return s;
}

RenderSettings small(int threads = 1) {
    RenderSettings rs;
    rs.width = rs.height = 16;
    rs.threads = threads;
    return rs;
}

TEST(PathReference, WhiteMirrorUnderAUniformMapIsTheMap) {
    const Scene s = lone_sphere([](Scene& sc) { return add_pbr(sc, Color(1.f), 1.f, 0.f); }, Color(0.3f, 0.6f, 0.9f));
    const Renderer r(s, small());
    PathSettings ps;
    ps.spp = 4;
    const Film f = path_trace(r, ps, 1);
    for (const Color& c : f.beauty) {
        EXPECT_NEAR(c.x, 0.3f, 1e-5f);
        EXPECT_NEAR(c.y, 0.6f, 1e-5f);
        EXPECT_NEAR(c.z, 0.9f, 1e-5f);
    }
}

// A white dielectric of roughness 1 under a uniform map of 1: what leaves the sphere toward the
// camera is its directional albedo, below 1 (the single-scattering GGX loses energy, Fresnel
// and Lambert share the rest) and above 0.85; the centre pixel, seen head-on, is within 1 % of
// the estimate of another seed (the noise of 4096 paths).
TEST(PathReference, DiffuseFurnaceIsTheAlbedo) {
    const Scene s = lone_sphere([](Scene& sc) { return add_pbr(sc, Color(1.f), 0.f, 1.f); }, Color(1.f));
    const Renderer r(s, small());
    PathSettings ps;
    ps.spp = 4096;
    const Film a = path_trace(r, ps, 1);
    ps.seed = 7;
    const Film b = path_trace(r, ps, 1);
    const Color ca = a.beauty[a.index(8, 8)], cb = b.beauty[b.index(8, 8)];
    EXPECT_GT(ca.x, 0.85f);
    EXPECT_LT(ca.x, 1.0f);
    EXPECT_NEAR(ca.x, cb.x, 0.01f);
    EXPECT_NE(ca.x, cb.x);  // the seed changes the samples
}

// A Lambertian plane (index of refraction 1: no Fresnel, no specular layer) under a sky with a
// small sun 2500 times brighter than the rest: what it reflects is its albedo times the map's
// irradiance (EnvironmentMap::brute_force_irradiance, every texel summed), within 2 % at 256 paths
// with light sampling and MIS; BSDF sampling alone would scatter by far more at that count.
TEST(PathReference, LambertianPlaneUnderASunIsAlbedoTimesIrradiance) {
    Scene s;
    Material m;
    m.name = "lambert";
    m.base_color = Vec4f(0.5f, 0.5f, 0.5f, 1.f);
    m.metallic = 0.f;
    m.roughness = 1.f;
    m.ior = 1.f;
    s.materials.push_back(m);
    Plane plane;
    plane.material = 0;
    s.planes.push_back(plane);
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 5, 0}, {0, -1, 0}, {0, 0, -1}, 1.0));
    Environment env = test::constant_environment(Color(0.2f));
    auto image = std::make_shared<EnvironmentImage>(*env.image);
    for (int y = 6; y < 8; ++y)
        for (int x = 20; x < 22; ++x) image->texels[size_t(y) * 64 + size_t(x)] = Color(500.f, 450.f, 400.f);
    env.image = image;
    test::light_with(s, env, 0);
    const Renderer r(s, small());
    const Color expected = r.view().environment()->brute_force_irradiance(Vec3f(0.f, 1.f, 0.f)) * 0.5f;
    PathSettings ps;
    ps.spp = 256;
    const Film f = path_trace(r, ps, 1);
    Color mean(0.f);
    for (const Color& c : f.beauty) mean += c / float(f.beauty.size());
    EXPECT_NEAR(mean.x / expected.x, 1.f, 0.02f) << mean.x << " " << expected.x;
    EXPECT_NEAR(mean.z / expected.z, 1.f, 0.02f) << mean.z << " " << expected.z;
    EXPECT_GT(expected.x, 2.f * 0.5f * 0.2f);  // the sun is most of it
}

TEST(PathReference, InsideAClosedBoxNothingArrives) {
    Scene s;
    const uint32_t m = add_pbr(s, Color(0.9f), 0.f, 0.5f);
    s.materials[m].double_sided = true;  // camera rays see single-sided faces from the front only
    add_mesh(s, make_box({-1, -1, -1}, {1, 1, 1}, m));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0.2, -0.3, 0.1}, {0, 0, -1}, {0, 1, 0}, 1.2));
    test::light_with(s, test::constant_environment(Color(1.f)), 0);
    const Renderer r(s, small());
    PathSettings ps;
    ps.spp = 8;
    const Film f = path_trace(r, ps, 1);
    for (const Color& c : f.beauty) ASSERT_EQ(c, Color(0.f));
}

TEST(PathReference, SameImageForAnyThreadCount) {
    const Scene s = lone_sphere([](Scene& sc) { return add_pbr(sc, Color(0.8f, 0.5f, 0.2f), 0.3f, 0.4f); }, Color(1.f));
    PathSettings ps;
    ps.spp = 16;
    ps.pixel_area = true;
    const Film one = path_trace(Renderer(s, small(1)), ps, 1);
    const Film two = path_trace(Renderer(s, small(2)), ps, 2);
    ASSERT_EQ(one.beauty.size(), two.beauty.size());
    for (size_t i = 0; i < one.beauty.size(); ++i) ASSERT_EQ(one.beauty[i], two.beauty[i]) << "pixel " << i;
}

TEST(PathReference, RefusesWhatItCannotSample) {
    Scene lit = lone_sphere([](Scene& sc) { return add_pbr(sc, Color(1.f), 0.f, 1.f); }, Color(1.f));
    lit.lights.push_back(point_light({0, 3, 0}, 1.f));
    EXPECT_THROW(path_trace(Renderer(lit, small()), PathSettings{}, 1), Error);
    Scene dark = lone_sphere([](Scene& sc) { return add_pbr(sc, Color(1.f), 0.f, 1.f); }, Color(1.f));
    dark.environment.reset();
    dark.lights.push_back(point_light({0, 3, 0}, 1.f));
    try {
        path_trace(Renderer(dark, small()), PathSettings{}, 1);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no environment"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace whitted
