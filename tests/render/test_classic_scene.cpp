// Whitted's (1980) formulas as tests: the reflection direction R = 2(N.L)N - L,
// Snell's law with n1/n2 and total internal reflection, the classic attenuation
// fat = min(1, 1/(c1 + c2 d + c3 d^2)), and the local model on an analytic sphere under one light
// at known pixels, through every accelerator backend.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/light_sample.h"
#include "shading/optics.h"

namespace whitted {
namespace {

Vec3f random_unit(std::mt19937& rng) {
    std::normal_distribution<float> g(0.f, 1.f);
    for (;;) {
        Vec3f v{g(rng), g(rng), g(rng)};
        if (length(v) > 1e-3f) return normalize(v);
    }
}

TEST(SeedFormulas, ReflectionIsTwiceNDotLTimesNMinusL) {
    std::mt19937 rng(1980);
    for (int i = 0; i < 1000; ++i) {
        const Vec3f N = random_unit(rng), L = random_unit(rng);
        const Vec3f R = reflect(L, N);
        const Vec3f want = N * (2.f * dot(N, L)) - L;
        EXPECT_NEAR(R.x, want.x, 1e-6f);
        EXPECT_NEAR(R.y, want.y, 1e-6f);
        EXPECT_NEAR(R.z, want.z, 1e-6f);
        // Angle of reflection = angle of incidence, in the plane of N and L, unit length.
        EXPECT_NEAR(dot(R, N), dot(L, N), 1e-5f);
        EXPECT_NEAR(length(R), 1.f, 1e-5f);
        EXPECT_NEAR(dot(cross(N, L), R), 0.f, 1e-5f);
    }
}

TEST(SeedFormulas, SnellsLawAndTotalInternalReflection) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> angle(0.f, 0.5f * kPi * 0.999f);
    const Vec3f N{0.f, 0.f, 1.f};
    for (float n1 : {1.f, 1.33f, 1.5f, 2.4f})
        for (float n2 : {1.f, 1.33f, 1.5f, 2.4f})
            for (int i = 0; i < 200; ++i) {
                const float theta_i = angle(rng);
                const Vec3f I{std::sin(theta_i), 0.f, -std::cos(theta_i)};  // travelling toward the surface
                const auto T = refract(I, N, n1 / n2);
                const float sin_t = n1 / n2 * std::sin(theta_i);
                if (sin_t >= 1.f) {
                    EXPECT_FALSE(T.has_value()) << n1 << "->" << n2 << " at " << theta_i;  // beyond the critical angle
                    continue;
                }
                ASSERT_TRUE(T.has_value()) << n1 << "->" << n2 << " at " << theta_i;
                // n1 sin(theta_i) = n2 sin(theta_t), continuing into the other side, in the plane of incidence.
                const float sin_theta_t = std::sqrt(T->x * T->x + T->y * T->y) / length(*T);
                EXPECT_NEAR(n1 * std::sin(theta_i), n2 * sin_theta_t, 2e-5f * n2);
                EXPECT_LT(T->z, 0.f);
                EXPECT_NEAR(T->y, 0.f, 1e-6f);
                EXPECT_GE(T->x, 0.f);
            }
    // Exactly around the critical angle of glass to air.
    const float critical = std::asin(1.f / 1.5f);
    auto at = [&](float theta) { return refract({std::sin(theta), 0.f, -std::cos(theta)}, N, 1.5f); };
    EXPECT_TRUE(at(critical - 1e-3f).has_value());
    EXPECT_FALSE(at(critical + 1e-3f).has_value());
}

TEST(SeedFormulas, ClassicAttenuation) {
    Light l = point_light({0, 0, 0}, 1.f);
    l.attenuation = Attenuation::Classic;
    l.classic_c = {0.5f, 0.1f, 0.02f};
    for (float d : {0.1f, 1.f, 3.f, 10.f, 100.f}) {
        const float want = std::min(1.f, 1.f / (0.5f + 0.1f * d + 0.02f * d * d));
        const LightSample s = sample_light(l, Vec3f{d, 0.f, 0.f});
        EXPECT_NEAR(s.intensity.x, want, 1e-6f * std::max(1.f, want)) << "d = " << d;
    }
}

// ---- the local model on an analytic sphere -----------------------------------------------------

constexpr int kSize = 50;
constexpr double kMag = 1.25;  // orthographic half extent
const Vec3d kLightPos{3.0, 4.0, 5.0};
const WhittedCoeffs kMaterial = [] {
    WhittedCoeffs c;
    c.kd = {0.7f, 0.5f, 0.3f};
    c.ka = {0.7f, 0.5f, 0.3f};
    c.ks = Color(0.4f);
    c.n = 20.f;
    return c;
}();
const Color kAmbient{0.1f};
const Color kBackground{0.f, 0.f, 0.25f};

Scene sphere_scene() {
    Scene s;
    Sphere sphere;
    sphere.center = {0, 0, 0};
    sphere.radius = 1.0;
    sphere.material = add_classic_material(s, kMaterial);
    s.spheres.push_back(sphere);
    Light l = point_light(kLightPos, 1.f);
    l.attenuation = Attenuation::Classic;  // c = (1, 0, 0): fat = 1, Whitted's (1980) unattenuated Is
    l.classic_c = {1.f, 0.f, 0.f};
    s.lights.push_back(l);
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, kMag));
    return s;
}

/// I = Ia Ka + Is (kd N.L + ks (N.H)^n) at the centre of pixel (x, y), computed in double.
Color expected_pixel(int x, int y) {
    const double sx = (2.0 * (x + 0.5) / kSize - 1.0) * kMag, sy = (1.0 - 2.0 * (y + 0.5) / kSize) * kMag;
    const double r2 = sx * sx + sy * sy;
    if (r2 >= 1.0) return kBackground;
    const Vec3d N{sx, sy, std::sqrt(1.0 - r2)};
    const Vec3d L = normalize(kLightPos - N);
    const Vec3d V{0, 0, 1};
    const Vec3d H = normalize(L + V);
    const double n_dot_l = dot(N, L);
    Color c = kAmbient * kMaterial.ka;
    if (n_dot_l > 0.0)
        c += kMaterial.kd * float(n_dot_l) + kMaterial.ks * float(std::pow(std::max(0.0, dot(N, H)), double(kMaterial.n)));
    return c;
}

class SphereLocalModel : public ::testing::TestWithParam<std::string> {};

TEST_P(SphereLocalModel, MatchesTheSeedAtKnownPixels) {
    const Scene scene = sphere_scene();
    RenderSettings rs;
    rs.width = rs.height = kSize;
    rs.threads = 1;
    rs.accel = GetParam();
    rs.integrator.ambient = kAmbient;
    rs.integrator.background = kBackground;
    const Film film = Renderer(scene, rs).render();
    // The centre (facing the camera), a lit point toward the light (highlight), a point lit at a
    // grazing angle near the limb, one the light cannot see (ambient only) and a miss.
    const int pixels[][2] = {{25, 25}, {31, 19}, {5, 25}, {14, 38}, {2, 2}};
    for (const auto& p : pixels) {
        const Color got = film.beauty[film.index(p[0], p[1])];
        const Color want = expected_pixel(p[0], p[1]);
        EXPECT_NEAR(got.x, want.x, 2e-4f) << "pixel " << p[0] << "," << p[1];
        EXPECT_NEAR(got.y, want.y, 2e-4f) << "pixel " << p[0] << "," << p[1];
        EXPECT_NEAR(got.z, want.z, 2e-4f) << "pixel " << p[0] << "," << p[1];
    }
    // And every pixel of the image, so a wrong root or normal anywhere fails.
    int bad = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const Color d = film.beauty[film.index(x, y)] - expected_pixel(x, y);
            if (std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) > 2e-4f) ++bad;
        }
    EXPECT_EQ(bad, 0);
}

INSTANTIATE_TEST_SUITE_P(AllBackends, SphereLocalModel,
                         ::testing::Values("embree", "bvh", "bvh:precision=double", "kdop", "grid", "octree", "brute"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                             std::string n = info.param;
                             for (char& ch : n)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });

}  // namespace
}  // namespace whitted
