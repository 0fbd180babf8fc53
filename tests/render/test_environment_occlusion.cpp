// The environment's light blocked by the scene (docs/environment.md, "Occlusion"): the ambient is
// shadowed over a fixed grid of directions and rough reflections trace rays over their lobe; what
// nothing blocks stays exactly as it was, what is enclosed receives nothing, a contact shadow has
// the size the geometry gives it, and the image is the same for any thread count and tile size.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include "accel/factory/create_accelerator.h"
#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/environment_map.h"
#include "tests/support/environment_scenes.h"

namespace whitted {
namespace {

using test::constant_environment;

WhittedCoeffs white() {
    WhittedCoeffs c;
    c.kd = c.ka = Color(1.f);
    return c;
}

IntegratorSettings occlusion(int budget) {
    IntegratorSettings s;
    s.env_occlusion = budget;
    return s;
}

/// A white sphere of radius `r` resting on a white infinite plane y = 0 at the origin, seen from
/// straight above by an orthographic camera covering x, z in [-2, 2], under a uniform map of 1.
/// Both take ambient ka = 1 and diffuse `kd` (the albedo the multi-bounce fit reads).
Scene sphere_on_plane(float r, float kd = 1.f) {
    Scene s;
    WhittedCoeffs c = white();
    c.kd = Color(kd);
    const uint32_t m = add_classic_material(s, c);
    Sphere sphere;
    sphere.center = {0, r, 0};
    sphere.radius = r;
    sphere.material = m;
    s.spheres.push_back(sphere);
    Plane plane;
    plane.material = m;
    s.planes.push_back(plane);
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 10, 0}, {0, -1, 0}, {0, 0, -1}, 2.0));
    test::light_with(s, constant_environment(Color(1.f)), kDefaultEnvironmentLights);
    return s;
}

/// Adds a rough gold sphere beside sphere_on_plane's sphere.
void add_gold_sphere(Scene& s) {
    Sphere gold;
    gold.center = {1.1, 0.5, 0.2};
    gold.radius = 0.5;
    gold.material = uint32_t(s.materials.size());
    s.materials.push_back(test::gltf_metal(Color(1.f, 0.77f, 0.34f), 0.35f));
    s.spheres.push_back(gold);
}

Film render(const Scene& scene, const IntegratorSettings& integrator, int size, RenderStats* stats = nullptr,
            int threads = 1, int tile = 32) {
    RenderSettings rs;
    rs.width = rs.height = size;
    rs.threads = threads;
    rs.tile_size = tile;
    rs.integrator = integrator;
    return Renderer(scene, rs).render(stats);
}

// A plane that nothing stands on, under a uniform map: occlusion traces its rays, none is blocked,
// and the image is exactly the unoccluded one.
TEST(EnvironmentOcclusion, OpenPlaneEqualsTheUnoccludedResult) {
    Scene s;
    Plane plane;
    plane.material = add_classic_material(s, white());
    s.planes.push_back(plane);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 2, 3}, normalize(Vec3d(0, -1, -1)), {0, 1, 0}, 0.8));
    test::light_with(s, constant_environment(Color(0.5f, 0.8f, 1.2f)), 0);
    RenderStats on_stats, off_stats;
    const Film on = render(s, occlusion(kDefaultEnvOcclusion), 24, &on_stats);
    const Film off = render(s, occlusion(0), 24, &off_stats);
    EXPECT_GT(on_stats.rays.occlusion, 0u);
    EXPECT_EQ(off_stats.rays.occlusion, 0u);
    for (size_t i = 0; i < on.beauty.size(); ++i) ASSERT_EQ(on.beauty[i], off.beauty[i]) << "pixel " << i;
    test::expect_near_rel(on.beauty[on.index(12, 20)], Color(0.5f, 0.8f, 1.2f), 0.02f);  // the plane, lit by the map
}

// A camera inside a closed box: no direction leaves it, so the environment's light reaches no
// point inside (without occlusion the unshadowed ambient lights the walls as if there were none).
TEST(EnvironmentOcclusion, InsideAClosedBoxNothingArrives) {
    Scene s;
    add_mesh(s, make_box({-1, -1, -1}, {1, 1, 1}, add_classic_material(s, white())));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0.2, -0.3, 0.1}, {0, 0, -1}, {0, 1, 0}, 1.2));
    test::light_with(s, constant_environment(Color(1.f)), kDefaultEnvironmentLights);
    const Film on = render(s, occlusion(kDefaultEnvOcclusion), 16);
    const Film off = render(s, occlusion(0), 16);
    for (size_t i = 0; i < on.beauty.size(); ++i) {
        ASSERT_EQ(on.beauty[i], Color(0.f)) << "pixel " << i;
        ASSERT_GT(off.beauty[i].x, 0.5f) << "pixel " << i;
    }
}

// Around a sphere of radius R touching a plane, a point of the plane at distance d from the
// contact sees the sphere over the cosine-weighted share (R / sqrt(d^2 + R^2))^3 of its
// hemisphere (the form factor of a sphere wholly above the point's horizon: cos(theta) R^2 / D^2
// with cos(theta) = R / D, D the distance to the centre); the rest of a uniform map of 1 arrives.
// The default budget is within 0.025 of that, 256 within 0.01, at distances from just
// outside the sphere's outline to 3.5 R. A black diffuse albedo (kd 0, ambient ka 1) gets back
// nothing from its neighbours: the plain fraction; a white one (kd 1) the multi-bounce fit of it.
TEST(EnvironmentOcclusion, ContactShadowHasTheAnalyticSize) {
    const float R = 0.5f;
    constexpr int kSize = 200;  // 0.02 world units a pixel
    for (const float kd : {0.f, 1.f}) {
        const Scene s = sphere_on_plane(R, kd);
        // What arrives at a point whose unblocked cosine-weighted share is f.
        auto arrives = [&](double f) { return double(multibounce_visibility(float(f), kd)); };
        for (const auto& [budget, tolerance] : {std::pair{kDefaultEnvOcclusion, 0.025}, std::pair{256, 0.01}}) {
            SCOPED_TRACE("kd " + std::to_string(kd) + ", budget " + std::to_string(budget));
            const Film film = render(s, occlusion(budget), kSize);
            // The open value: a corner, far from the sphere (the map's SH projection is not exactly 1).
            const double corner2 = 2.0 * 1.99 * 1.99 + double(R) * R;
            const double open = film.beauty[film.index(0, 0)].x / arrives(1.0 - std::pow(double(R) * R / corner2, 1.5));
            for (const double d : {0.56, 0.6, 0.75, 1.0, 1.25, 1.75}) {
                const int px = kSize / 2 + int(std::lround(d / 0.02 - 0.5));
                const double x = (px + 0.5) * 0.02 - 2.0, z = (kSize / 2 + 0.5) * 0.02 - 2.0;
                const double D2 = x * x + z * z + double(R) * R;
                const double fraction = 1.0 - std::pow(double(R) * R / D2, 1.5);
                EXPECT_NEAR(film.beauty[film.index(px, kSize / 2)].x, open * arrives(fraction), tolerance)
                    << "at distance " << x;
                if (kd > 0.f && fraction < 0.9) {  // the neighbours' light is visible
                    EXPECT_GT(film.beauty[film.index(px, kSize / 2)].x, open * fraction + 0.03) << "at distance " << x;
                }
            }
        }
    }
}

// Jimenez et al.'s multi-bounce fit at hand-computed values: the ends stay put, a black
// receiver keeps its visibility, v = 0.5 with albedo 0.8 gives
// ((1.29992 * 0.5 - 3.19438) * 0.5 + 2.89446) * 0.5 = 0.811125.
TEST(EnvironmentOcclusion, MultibounceFitAtKnownValues) {
    EXPECT_EQ(multibounce_visibility(0.f, 0.8f), 0.f);
    EXPECT_EQ(multibounce_visibility(1.f, 0.8f), 1.f);
    EXPECT_EQ(multibounce_visibility(1.f, 1.f), 1.f);
    for (const float v : {0.1f, 0.3f, 0.5f, 0.9f}) EXPECT_NEAR(multibounce_visibility(v, 0.f), v, 1e-6f);
    EXPECT_NEAR(multibounce_visibility(0.5f, 0.8f), 0.811125f, 1e-5f);
    EXPECT_EQ(multibounce_visibility(std::nanf(""), 0.8f), 0.f);
    const Color c = multibounce_visibility(Color(0.5f), Color(0.f, 0.8f, 2.f));  // albedo clamped to [0, 1]
    EXPECT_NEAR(c.x, 0.5f, 1e-6f);
    EXPECT_NEAR(c.y, 0.811125f, 1e-5f);
    EXPECT_NEAR(c.z, multibounce_visibility(0.5f, 1.f), 1e-6f);
}

// The same image for 1 thread and 16-pixel tiles as for 2 threads and 64-pixel tiles, with
// adaptive anti-aliasing: the direction sets are fixed, nothing depends on the order of work.
TEST(EnvironmentOcclusion, DeterministicAcrossThreadsAndTiles) {
    Scene s = sphere_on_plane(0.5f);
    add_gold_sphere(s);
    s.cameras.front() = make_camera(CameraType::Perspective, {0, 1.5, 4}, normalize(Vec3d(0, -0.3, -1)), {0, 1, 0}, 0.7);
    test::light_with(s, constant_environment(Color(1.f)), kDefaultEnvironmentLights);
    RenderSettings rs;
    rs.width = rs.height = 64;
    rs.aa.mode = AaMode::Adaptive;
    rs.threads = 1;
    rs.tile_size = 16;
    RenderStats one_stats, two_stats;
    const Film one = Renderer(s, rs).render(&one_stats);
    rs.threads = 2;
    rs.tile_size = 64;
    const Film two = Renderer(s, rs).render(&two_stats);
    EXPECT_GT(one_stats.rays.occlusion, 0u);
    EXPECT_EQ(one_stats.rays, two_stats.rays);
    for (size_t i = 0; i < one.beauty.size(); ++i) ASSERT_EQ(one.beauty[i], two.beauty[i]) << "pixel " << i;
}

// A rough metal sphere resting on a red floor under a white map: with occlusion its glossy rays
// find the floor, so the lower half reflects red; without, it reflects the white map.
TEST(EnvironmentOcclusion, RoughReflectionSeesTheScene) {
    Scene s;
    WhittedCoeffs red;
    red.kd = red.ka = Color(0.9f, 0.05f, 0.05f);
    Plane floor;
    floor.material = add_classic_material(s, red);
    s.planes.push_back(floor);
    Sphere ball;
    ball.center = {0, 1, 0};
    ball.radius = 1;
    ball.material = uint32_t(s.materials.size());
    s.materials.push_back(test::gltf_metal(Color(0.95f), 0.3f));
    s.spheres.push_back(ball);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 1, 4}, {0, 0, -1}, {0, 1, 0}, 0.6));
    test::light_with(s, constant_environment(Color(1.f)), kDefaultEnvironmentLights);
    const Film on = render(s, occlusion(kDefaultEnvOcclusion), 48);
    const Film off = render(s, occlusion(0), 48);
    const Color lower_on = on.beauty[on.index(24, 36)], lower_off = off.beauty[off.index(24, 36)];
    EXPECT_LT(lower_on.y, 0.6f * lower_on.x) << "the floor's red in the lower half";
    EXPECT_GT(lower_off.y, 0.95f * lower_off.x) << "the white map only";
    // The upper half faces the open sky either way.
    const Color upper_on = on.beauty[on.index(24, 8)], upper_off = off.beauty[off.index(24, 8)];
    test::expect_near_rel(upper_on, upper_off, 0.05f);
}

// Scenes without an environment never trace an occlusion ray: the classic scenes render bit for
// bit as with occlusion off.
TEST(EnvironmentOcclusion, ClassicScenesAreUnaffected) {
    const Scene s = load_scene(std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json");
    RenderStats on_stats;
    const Film on = render(s, occlusion(kDefaultEnvOcclusion), 48, &on_stats);
    const Film off = render(s, occlusion(0), 48);
    EXPECT_EQ(on_stats.rays.occlusion, 0u);
    for (size_t i = 0; i < on.beauty.size(); ++i) ASSERT_EQ(on.beauty[i], off.beauty[i]) << "pixel " << i;
}

/// Forwards to an accelerator and counts the shadow rays that come as batch queries.
class BatchCounter final : public Accelerator {
public:
    explicit BatchCounter(const Accelerator& inner) : m_inner(inner) {}
    Hit intersect(const Ray& ray, RayKind kind) const override { return m_inner.intersect(ray, kind); }
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        m_inner.intersect(rays, kind, hits);
    }
    Color transmittance(const Ray& ray) const override { return m_inner.transmittance(ray); }
    void transmittance(std::span<const Ray> rays, std::span<Color> out) const override {
        batched += rays.size();
        m_inner.transmittance(rays, out);
        for (const Color& c : out) partial += !is_black(c) && !(c == Color(1.f));
    }
    std::string name() const override { return m_inner.name(); }
    RayOffsetPolicy ray_offset() const override { return m_inner.ray_offset(); }
    AccelStats stats() const override { return m_inner.stats(); }
    mutable std::atomic<uint64_t> batched{0};
    mutable std::atomic<uint64_t> partial{0};  ///< answers between 0 and 1 (through transparent occluders)

private:
    const Accelerator& m_inner;
};

// Which of an environment's extracted lights take a shadow ray at a point, and which occlusion
// cells a ray, depends on their potentials alone (Ward's test), so each point's rays go to the
// accelerator as one batch query (Embree: 16-wide packets): every shadow and occlusion ray of
// this scene does. The image and the ray counts equal those of the same rays one by one
// (`shadow_packet=1`) bit for bit, under a map whose lights Ward's test splits (a bright patch in
// a dimmer gradient), with occluders on an edge (the refined cells' batches of four) and a glass
// sphere whose shadow the lanes' transmittance products make.
TEST(EnvironmentOcclusion, BatchedShadowQueriesEqualRayByRay) {
    Scene s = sphere_on_plane(0.5f, 0.7f);
    add_gold_sphere(s);
    WhittedCoeffs glass;
    glass.kt = Color(0.7f, 0.8f, 0.9f);
    glass.ks = Color(0.1f);
    glass.ior = 1.5f;
    Sphere clear;
    clear.center = {-1.0, 0.4, 0.6};
    clear.radius = 0.4;
    clear.material = add_classic_material(s, glass);
    s.spheres.push_back(clear);
    s.cameras.front() = make_camera(CameraType::Perspective, {0, 1.5, 4}, normalize(Vec3d(0, -0.3, -1)), {0, 1, 0}, 0.7);
    Environment env = constant_environment(Color(1.f));
    auto image = std::make_shared<EnvironmentImage>(*env.image);
    for (int y = 0; y < image->height; ++y)
        for (int x = 0; x < image->width; ++x)
            image->texels[size_t(y * image->width + x)] =
                (x >= 20 && x < 24 && y >= 6 && y < 10) ? Color(60.f, 55.f, 40.f)
                                                         : Color(0.2f + 0.02f * float(x % 16), 0.3f, 0.5f - 0.01f * float(y));
    env.image = image;
    test::light_with(s, env, kDefaultEnvironmentLights);
    RenderSettings rs;
    rs.width = rs.height = 48;
    rs.aa.mode = AaMode::Adaptive;
    rs.threads = 1;
    rs.integrator.min_weight = 1.f / 255.f;  // the renderer's default: Ward's test leaves dim lights untested
    const Renderer renderer(s, rs);
    ASSERT_TRUE(renderer.kernel().transmission);  // shadow rays multiply transmittances
    const auto single = create_accelerator("embree:shadow_packet=1", s, renderer.view(), AccelConfig{rs.robust});
    const BatchCounter one_by_one(*single), packets(renderer.accelerator());
    RenderStats a, b;
    const Film fa = renderer.render(rs.aa, rs.integrator, one_by_one, &a);
    const Film fb = renderer.render(rs.aa, rs.integrator, packets, &b);
    EXPECT_EQ(a.rays, b.rays);
    EXPECT_GT(a.rays.shadow_skipped_dim, 0u);  // Ward's test left lights untested
    EXPECT_GT(a.rays.occlusion, 0u);
    EXPECT_EQ(packets.batched.load(), a.rays.shadow + a.rays.occlusion);
    EXPECT_EQ(one_by_one.batched.load(), packets.batched.load());
    EXPECT_GT(packets.partial.load(), 0u);  // through the glass
    for (size_t i = 0; i < fa.beauty.size(); ++i) ASSERT_EQ(fa.beauty[i], fb.beauty[i]) << "pixel " << i;
}

}  // namespace
}  // namespace whitted
