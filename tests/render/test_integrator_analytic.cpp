// Analytic scenes with closed-form pixel values (pbrt integrators_test style): each checks one
// term of I = Ia Ka + sum Is fat s (kd N.L + ks (N.H)^n) + Ks R + Kt T against a hand computation.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted {
namespace {

constexpr float kTol = 1e-4f;

Color render_pixel(const Scene& scene, int width, int height, int x, int y, int max_depth = 5,
                   Color ambient = Color(0.1f)) {
    RenderSettings rs;
    rs.width = width;
    rs.height = height;
    rs.threads = 1;
    rs.integrator.max_depth = max_depth;
    rs.integrator.ambient = ambient;
    Renderer renderer(scene, rs);
    Film film = renderer.render();
    return film.beauty[film.index(x, y)];
}

void expect_color_near(Color got, Color want, float tol = kTol) {
    EXPECT_NEAR(got.x, want.x, tol);
    EXPECT_NEAR(got.y, want.y, tol);
    EXPECT_NEAR(got.z, want.z, tol);
}

WhittedCoeffs diffuse(Color kd, Color ks = Color(0.f), float n = 1.f) {
    WhittedCoeffs c;
    c.kd = kd;
    c.ka = kd;
    c.ks = ks;
    c.n = n;
    return c;
}

WhittedCoeffs emitter(Color e) {
    WhittedCoeffs c;
    c.emission = e;
    return c;
}

/// Floor z = 0 spanning [-10, 10]^2, facing +z.
void add_floor(Scene& s, uint32_t mat) {
    add_mesh(s, make_quad({-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, mat));
}

Camera top_down_ortho(double mag) {
    return make_camera(CameraType::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, mag);
}

TEST(IntegratorAnalytic, DiffusePlaneUnderPointLightAtCentre) {
    Scene s;
    const Color kd{0.5f, 0.6f, 0.7f};
    add_floor(s, add_classic_material(s, diffuse(kd)));
    s.lights.push_back(point_light({0, 0, 2}, 8.f));
    s.cameras.push_back(top_down_ortho(1.0));
    // I = Ia Ka + Is fat kd (N.L) = 0.1 kd + 8 / 2^2 * kd * 1
    expect_color_near(render_pixel(s, 1, 1, 0, 0), kd * 2.1f);
}

TEST(IntegratorAnalytic, DiffusePlaneOffCentreFollowsInverseSquareAndCosine) {
    Scene s;
    const Color kd{0.5f, 0.6f, 0.7f};
    add_floor(s, add_classic_material(s, diffuse(kd)));
    s.lights.push_back(point_light({0, 0, 2}, 8.f));
    s.cameras.push_back(top_down_ortho(3.0));
    // Pixel (2, 1) of a 3x3 image with half-extent 3 looks at (2, 0, 0): d^2 = 8, N.L = 2/sqrt(8).
    const float e = 8.f / 8.f * (2.f / std::sqrt(8.f));
    expect_color_near(render_pixel(s, 3, 3, 2, 1), kd * (0.1f + e));
}

TEST(IntegratorAnalytic, BlinnPhongHighlight) {
    Scene s;
    const Color kd{0.2f}, ks{0.3f};
    const float n = 10.f;
    add_floor(s, add_classic_material(s, diffuse(kd, ks, n)));
    s.lights.push_back(point_light({0, 0, 2}, 8.f));
    s.cameras.push_back(top_down_ortho(3.0));
    // At (2, 0, 0): L = (-2, 0, 2)/sqrt 8, V = (0, 0, 1), H = normalize(L + V).
    const Vec3f L = normalize(Vec3f{-2, 0, 2});
    const Vec3f H = normalize(L + Vec3f{0, 0, 1});
    const float e = 1.f;  // 8 / d^2
    const Color want = kd * 0.1f + (kd * L.z + ks * std::pow(H.z, n)) * e;
    expect_color_near(render_pixel(s, 3, 3, 2, 1), want);
}

// The specular cutoff: where n (1 - N.H) >= 17 the highlight (< e^-17 = 4.2e-8 of ks Is) is not
// evaluated, and a point whose light term is then 0 casts no shadow ray. A highlight-only floor
// (kd = ka = 0, no ambient) seen at the origin, the light at (2, 0, 2): Is fat = 8 / 8 = 1 and
// N.H = cos(22.5 deg) = 0.924. With n = 300 the highlight lies past the cutoff: the pixel is 0
// (within 4.2e-8 ks of the exact value) and no shadow ray is cast; with n = 200 (n (1 - N.H) =
// 15.2) it is evaluated as the formula says, under one shadow ray. Both kernels agree.
TEST(IntegratorAnalytic, HighlightBelowTwoToMinus24OfKsIsNotEvaluatedNorShadowed) {
    const Color ks{0.3f};
    const Vec3f L = normalize(Vec3f{2, 0, 2});
    const float n_dot_h = normalize(L + Vec3f{0, 0, 1}).z;
    for (const float n : {300.f, 200.f})
        for (const bool specialize : {false, true}) {
            SCOPED_TRACE(testing::Message() << "n " << n << " specialize " << specialize);
            Scene s;
            add_floor(s, add_classic_material(s, diffuse(Color(0.f), ks, n)));
            s.lights.push_back(point_light({2, 0, 2}, 8.f));
            s.cameras.push_back(top_down_ortho(0.5));
            RenderSettings rs;
            rs.width = rs.height = 1;
            rs.threads = 1;
            rs.integrator.ambient = Color(0.f);
            rs.integrator.specialize = specialize;
            RenderStats stats;
            const float got = Renderer(s, rs).render(&stats).beauty[0].x;
            const float exact = ks.x * std::pow(n_dot_h, n);
            ASSERT_GT(exact, 0.f);
            EXPECT_LE(std::abs(got - exact), 4.2e-8f * ks.x);
            if (n * (1.f - n_dot_h) >= 17.f) {
                EXPECT_EQ(got, 0.f);
                EXPECT_EQ(stats.rays.shadow, 0u);
                EXPECT_EQ(stats.rays.shadow_skipped_zero, 1u);
            } else {
                EXPECT_NEAR(got, exact, exact * 1e-4f);
                EXPECT_EQ(stats.rays.shadow, 1u);
                EXPECT_EQ(stats.rays.shadow_skipped_zero, 0u);
            }
        }
}

TEST(IntegratorAnalytic, NoLightFromBehindTheSurface) {
    Scene s;
    add_floor(s, add_classic_material(s, diffuse(Color(0.5f))));
    s.lights.push_back(point_light({0, 0, -2}, 8.f));  // below the floor
    s.cameras.push_back(top_down_ortho(1.0));
    expect_color_near(render_pixel(s, 1, 1, 0, 0), Color(0.05f));  // ambient only
}

TEST(IntegratorAnalytic, MirrorShowsWhatItReflects) {
    Scene s;
    WhittedCoeffs mirror;
    mirror.kr = Color(0.9f);
    add_floor(s, add_classic_material(s, mirror));
    // An emitter above the camera, facing down; the camera ray starts below it.
    const Color e{0.2f, 0.4f, 0.8f};
    add_mesh(s, make_quad({-1, -1, 10}, {-1, 1, 10}, {1, 1, 10}, {1, -1, 10}, add_classic_material(s, emitter(e))));
    s.cameras.push_back(top_down_ortho(1.0));
    expect_color_near(render_pixel(s, 1, 1, 0, 0), e * 0.9f);
    // Depth 0 means no reflected ray at all.
    expect_color_near(render_pixel(s, 1, 1, 0, 0, 0), Color(0.f));
}

/// Floor lit from (0,0,4) so the irradiance at the origin is 1; camera views the origin
/// obliquely, below any occluder placed above it.
Scene shadow_scene(float kd) {
    Scene s;
    add_floor(s, add_classic_material(s, diffuse(Color(kd))));
    s.lights.push_back(point_light({0, 0, 4}, 16.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {3, 0, 1}, {-3, 0, -1}, {0, 0, 1}, 0.5));
    return s;
}

TEST(IntegratorAnalytic, ShadowBehindOpaqueOccluder) {
    Scene s = shadow_scene(0.5f);
    add_mesh(s, make_quad({-0.5f, -0.5f, 2}, {0.5f, -0.5f, 2}, {0.5f, 0.5f, 2}, {-0.5f, 0.5f, 2},
                          add_classic_material(s, diffuse(Color(0.3f)))));
    expect_color_near(render_pixel(s, 1, 1, 0, 0), Color(0.05f));  // Ia Ka only
}

TEST(IntegratorAnalytic, ShadowThroughThinTransparentOccluderIsKt) {
    Scene s = shadow_scene(0.5f);
    WhittedCoeffs glass;
    glass.kt = Color(0.5f, 0.25f, 1.f);
    add_mesh(s, make_quad({-0.5f, -0.5f, 2}, {0.5f, -0.5f, 2}, {0.5f, 0.5f, 2}, {-0.5f, 0.5f, 2},
                          add_classic_material(s, glass)));
    // The shadow ray crosses the quad exactly on the diagonal shared by its two triangles:
    // the crossing must still count once.
    expect_color_near(render_pixel(s, 1, 1, 0, 0), Color(0.05f) + Color(0.5f) * glass.kt);
}

TEST(IntegratorAnalytic, DuplicateReportsOfOneCrossingCountOnce) {
    // The same quad stored twice in one mesh: the shadow ray meets two primitives of one
    // (mesh, instance) at the same t, which is one surface crossing (as when Embree reports a
    // primitive twice or both triangles of a shared edge). Without de-duplication: Kt^2.
    Scene s = shadow_scene(0.5f);
    WhittedCoeffs glass;
    glass.kt = Color(0.5f);
    Mesh quad = make_quad({-0.5f, -0.4f, 2}, {0.5f, -0.4f, 2}, {0.5f, 0.6f, 2}, {-0.5f, 0.6f, 2},
                          add_classic_material(s, glass));
    quad.indices.insert(quad.indices.end(), {0, 1, 2, 0, 2, 3});
    add_mesh(s, quad);
    expect_color_near(render_pixel(s, 1, 1, 0, 0), Color(0.05f) + Color(0.5f) * glass.kt);
}

TEST(IntegratorAnalytic, ShadowThroughClosedTransparentOccluderIsKtSquared) {
    Scene s = shadow_scene(0.5f);
    WhittedCoeffs glass;
    glass.kt = Color(0.5f, 0.8f, 1.f);
    add_mesh(s, make_box({-0.5f, -0.5f, 1.5f}, {0.5f, 0.5f, 2.5f}, add_classic_material(s, glass)));
    expect_color_near(render_pixel(s, 1, 1, 0, 0), Color(0.05f) + Color(0.5f) * glass.kt * glass.kt);
}

TEST(IntegratorAnalytic, GlassSlabOffsetsTheRayBySnellsLaw) {
    // A ray at 30 degrees enters a slab of thickness 1 (ior 1.5) at the origin. Inside,
    // sin(theta_t) = 0.5 / 1.5, so it exits displaced by tan(theta_t) and continues at 30 degrees:
    // it reaches z = -2 at x = tan(theta_t) + tan(30) = 0.9309 (straight through: 1.1547).
    const double theta_t = std::asin(0.5 / 1.5);
    const double x_hit = std::tan(theta_t) + std::tan(M_PI / 6.0);
    const Color e{0.3f, 0.6f, 0.9f};
    auto build = [&](double target_x) {
        Scene s;
        WhittedCoeffs glass;
        glass.kt = Color(1.f);
        glass.ior = 1.5f;
        glass.thin = false;
        add_mesh(s, make_box({-50, -50, -1}, {50, 50, 0}, add_classic_material(s, glass)));
        const float tx = float(target_x);
        add_mesh(s, make_quad({tx - 0.05f, -0.05f, -2}, {tx + 0.05f, -0.05f, -2}, {tx + 0.05f, 0.05f, -2},
                              {tx - 0.05f, 0.05f, -2}, add_classic_material(s, emitter(e))));
        const Vec3d d{std::sin(M_PI / 6.0), 0, -std::cos(M_PI / 6.0)};
        s.cameras.push_back(make_camera(CameraType::Orthographic, d * -5.0, d, {0, 1, 0}, 0.01));
        return s;
    };
    expect_color_near(render_pixel(build(x_hit), 1, 1, 0, 0, 5, Color(0.f)), e);
    // A target where an unbent ray would land is missed: the test can fail.
    expect_color_near(render_pixel(build(2.0 * std::tan(M_PI / 6.0)), 1, 1, 0, 0, 5, Color(0.f)), Color(0.f));
}

/// Closed triangular prism: right isosceles cross-section A(0,0) B(2,0) C(0,2) in (x, z),
/// extruded over y in [-5, 5]; faces oriented outward.
Mesh make_prism(uint32_t material) {
    Mesh m;
    m.material = material;
    const Vec3f c{2.f / 3.f, 0.f, 2.f / 3.f};  // centroid
    auto tri = [&](Vec3f a, Vec3f b, Vec3f d) {
        Vec3f n = normalize(cross(b - a, d - a));
        if (dot(n, a - c) < 0.f) {
            std::swap(b, d);
            n = -n;
        }
        uint32_t base = uint32_t(m.positions.size());
        for (Vec3f p : {a, b, d}) {
            m.positions.push_back(p);
            m.normals.push_back(n);
        }
        for (uint32_t i = 0; i < 3; ++i) m.indices.push_back(base + i);
    };
    const Vec3f A0{0, -5, 0}, B0{2, -5, 0}, C0{0, -5, 2}, A1{0, 5, 0}, B1{2, 5, 0}, C1{0, 5, 2};
    tri(A0, B0, C0);
    tri(A1, B1, C1);
    for (auto [p, q] : {std::pair{A0, B0}, std::pair{B0, C0}, std::pair{C0, A0}}) {
        const Vec3f p1 = p + Vec3f{0, 10, 0}, q1 = q + Vec3f{0, 10, 0};
        tri(p, q, q1);
        tri(p, q1, p1);
    }
    return m;
}

TEST(IntegratorAnalytic, TotalInternalReflectionInsidePrism) {
    // A ray enters the bottom leg straight up at x = 0.5, meets the hypotenuse at 45 degrees
    // (critical angle for ior 1.5 is 41.8 degrees), reflects totally toward -x and leaves through
    // the left leg at z = 1.5, reaching an emitter at x = -2.
    const Color e{0.9f, 0.5f, 0.1f};
    auto build = [&](float target_z) {
        Scene s;
        WhittedCoeffs glass;
        glass.kt = Color(1.f);
        glass.ior = 1.5f;
        glass.thin = false;
        add_mesh(s, make_prism(add_classic_material(s, glass)));
        add_mesh(s, make_quad({-2, -0.1f, target_z - 0.1f}, {-2, 0.1f, target_z - 0.1f},
                              {-2, 0.1f, target_z + 0.1f}, {-2, -0.1f, target_z + 0.1f},
                              add_classic_material(s, emitter(e))));
        s.cameras.push_back(make_camera(CameraType::Orthographic, {0.5, 0, -3}, {0, 0, 1}, {0, 1, 0}, 0.01));
        return s;
    };
    expect_color_near(render_pixel(build(1.5f), 1, 1, 0, 0, 5, Color(0.f)), e);
    // Depth 2 stops before the ray leaves the prism (camera 0, refract 1, TIR 2, exit 3).
    expect_color_near(render_pixel(build(1.5f), 1, 1, 0, 0, 2, Color(0.f)), Color(0.f));
}

TEST(IntegratorAnalytic, NegativeMaxDepthIsRejected) {
    Scene s;
    add_floor(s, add_classic_material(s, diffuse(Color(0.5f))));
    s.cameras.push_back(top_down_ortho(1.0));
    RenderSettings rs;
    rs.integrator.max_depth = -1;
    EXPECT_THROW(Renderer(s, rs), Error);
    rs.integrator.max_depth = 5;
    rs.camera = 3;
    EXPECT_THROW(Renderer(s, rs), Error);
}

// Hall & Greenberg (1983) adaptive tree depth: two facing half-silvered mirrors, the upper one
// also emitting e. Along the camera ray the branch weights are 0.5, 0.25, 0.125, ...; with
// min_weight w only the branches whose weight is >= w are traced, so the pixel is the partial sum
// of the geometric series e (0.5 + 0.125 + ...) and the reflection-ray count says where it stopped.
TEST(IntegratorAnalytic, MinWeightCutsTheRayTreeWhereTheWeightFallsBelowIt) {
    Scene s;
    WhittedCoeffs lower;
    lower.kr = Color(0.5f);
    add_floor(s, add_classic_material(s, lower));
    WhittedCoeffs upper = emitter(Color(1.f));
    upper.kr = Color(0.5f);
    add_mesh(s, make_quad({-10, -10, 10}, {-10, 10, 10}, {10, 10, 10}, {10, -10, 10}, add_classic_material(s, upper)));
    s.cameras.push_back(top_down_ortho(1.0));
    auto run = [&](float min_weight, uint64_t* reflections) {
        RenderSettings rs;
        rs.width = rs.height = 1;
        rs.threads = 1;
        rs.integrator.max_depth = 50;
        rs.integrator.ambient = Color(0.f);
        rs.integrator.min_weight = min_weight;
        Renderer renderer(s, rs);
        RenderStats stats;
        Film film = renderer.render(&stats);
        *reflections = stats.rays.reflection;
        return film.beauty[0].x;
    };
    uint64_t refl = 0;
    EXPECT_NEAR(run(0.6f, &refl), 0.f, 1e-6f);  // 0.5 < 0.6: not even the first bounce
    EXPECT_EQ(refl, 0u);
    EXPECT_NEAR(run(0.5f, &refl), 0.5f, 1e-6f);  // the first bounce only (weight exactly 0.5)
    EXPECT_EQ(refl, 1u);
    EXPECT_NEAR(run(0.1f, &refl), 0.5f + 0.125f, 1e-6f);  // weights 0.5, 0.25, 0.125
    EXPECT_EQ(refl, 3u);
    // No cutoff: the series converges to e * 0.5 / (1 - 0.25) = 2/3, ended by max_depth 50.
    EXPECT_NEAR(run(0.f, &refl), 2.f / 3.f, 1e-5f);
    EXPECT_EQ(refl, 50u);
}

}  // namespace
}  // namespace whitted

namespace whitted {
namespace {

// Lights that cannot reach a point cast no shadow ray: one beyond its glTF range, a spot whose
// cone misses the floor and a light below the floor (N.L <= 0). Only the one light that reaches
// the floor casts a shadow ray; the pixel is its diffuse term alone. Both kernels agree.
TEST(IntegratorAnalytic, LightsThatCannotReachAPointCastNoShadowRay) {
    Scene s;
    add_floor(s, add_classic_material(s, diffuse(Color(0.5f))));
    s.cameras.push_back(top_down_ortho(0.5));
    Light far = point_light({0, 0, 4}, 100.f);
    far.range = 3.f;  // 4 away: the window is exactly 0
    s.lights.push_back(far);
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {0, 0, 2};
    spot.direction = normalize(Vec3d(1, 0, 0.2));  // points away from the floor
    spot.outer_cone = 0.3f;
    spot.intensity = 100.f;
    s.lights.push_back(spot);
    s.lights.push_back(point_light({0, 0, -2}, 100.f));  // below the floor
    s.lights.push_back(point_light({0, 0, 2}, 4.f));     // the one that counts: E = 4 / 2^2 = 1
    for (const bool specialize : {false, true}) {
        RenderSettings rs;
        rs.width = rs.height = 1;
        rs.threads = 1;
        rs.integrator.ambient = Color(0.f);
        rs.integrator.specialize = specialize;
        Renderer renderer(s, rs);
        RenderStats stats;
        const Film film = renderer.render(&stats);
        EXPECT_EQ(stats.rays.shadow, 1u);
        EXPECT_EQ(stats.rays.shadow_skipped_unreached, 2u);  // range and cone
        EXPECT_EQ(stats.rays.shadow_skipped_facing, 1u);     // below the surface
        expect_color_near(film.beauty[0], Color(0.5f));
    }
}

}  // namespace
}  // namespace whitted
