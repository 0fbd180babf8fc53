// The environment (docs/environment.md): the white furnace, a sun's light, rotation, the
// irradiance of the bundled maps, seams and poles, MIP level choice, the GGX prefilter, and
// loading maps from files.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "benchmarks/irradiance_check.h"
#include "importers/environment_image.h"
#include "core/error.h"
#include "shading/environment_map.h"

namespace whitted {
namespace {

namespace fs = std::filesystem;

/// A w x h environment whose texel (x, y) is texel(x, y).
Environment make_environment(int w, int h, const std::function<Color(int, int)>& texel, float rotation_deg = 0.f) {
    auto image = std::make_shared<EnvironmentImage>();
    image->name = "test";
    image->width = w;
    image->height = h;
    image->texels.resize(size_t(w) * size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) image->texels[size_t(y) * size_t(w) + size_t(x)] = texel(x, y);
    Environment env;
    env.image = image;
    env.rotation_deg = rotation_deg;
    return env;
}

Environment constant_environment(const Color& L) { return make_environment(64, 32, [&](int, int) { return L; }); }

/// A black 512 x 256 map but for a 2 x 2 sun of 1e4 at texels [sx, sx+2) x [sy, sy+2).
constexpr int kSunW = 512, kSunH = 256, kSunX = 300, kSunY = 70;
constexpr float kSun = 1e4f;
Environment sun_environment(float rotation_deg = 0.f) {
    return make_environment(
        kSunW, kSunH,
        [](int x, int y) { return x >= kSunX && x < kSunX + 2 && y >= kSunY && y < kSunY + 2 ? Color(kSun) : Color(0.f); },
        rotation_deg);
}

double texel_sr(int y, int w, int h) {
    return 2.0 * kPiD / w * (std::cos(kPiD * y / h) - std::cos(kPiD * (y + 1) / h));
}

Vec3f texel_dir(int x, int y, int w, int h) { return latlong_direction((x + 0.5f) / float(w), (y + 0.5f) / float(h)); }

float angle_between(const Vec3f& a, const Vec3f& b) {
    return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.f, 1.f));
}

/// The 6 axis normals.
const std::vector<Vec3f>& axes() {
    static const std::vector<Vec3f> a{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    return a;
}

Environment bundled(const std::string& name) {
    std::vector<std::string> warnings;
    Environment env;
    env.image = std::make_shared<EnvironmentImage>(
        load_environment_image(resolve_environment_name(name), size_t(1) << 30, warnings));
    return env;
}

Vec3f rotate_y(const Vec3f& d, float degrees) {
    const float a = degrees * kPi / 180.f, c = std::cos(a), s = std::sin(a);
    return {c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

// ---- units: the white furnace ----------------------------------------------------------------

TEST(Environment, WhiteFurnace) {
    const Color L{0.5f, 0.8f, 1.2f};
    const EnvironmentMap map(constant_environment(L), 1);
    std::vector<Vec3f> normals = axes();
    for (const Vec3f& n : random_directions(50, 7)) normals.push_back(n);
    for (int n_lights : {0, 1, 16}) {
        const EnvironmentLighting lighting = map.split(n_lights);
        for (const Vec3f& n : normals) {
            // kd = ka = 1: sum_k I_k max(0, N.d_k) + E_residual(N) is the sphere's radiance.
            Color e = lighting.residual_irradiance(n);
            for (const ExtractedLight& l : lighting.lights) e += l.intensity * std::max(0.f, dot(n, l.direction));
            EXPECT_LT(max_relative_error(e, L), 0.01f) << n_lights << " lights, normal " << n.x << " " << n.y << " " << n.z;
            EXPECT_LT(max_relative_error(lighting.irradiance(n), L), 0.01f);
        }
    }
    // The reference integration agrees with the units too.
    EXPECT_LT(max_relative_error(map.brute_force_irradiance({0, 1, 0}), L), 0.01f);
    EXPECT_LT(max_relative_error(map.mean(), L), 1e-5f);
}

TEST(Environment, SplitConservesPower) {
    const EnvironmentMap map(bundled("studio"), 1);
    const Color total = map.mean() * (4.f * kPi);
    for (int n : {0, 1, 2, 3, 4, 5, 16, 64}) {
        const EnvironmentLighting lighting = map.split(n);
        EXPECT_LE(int(lighting.lights.size()), n);
        Color lights(0.f);
        for (const ExtractedLight& l : lighting.lights) lights += l.intensity * kPi;
        EXPECT_LT(max_relative_error(lights, lighting.extracted_power), 1e-4f) << n;
        EXPECT_LT(max_relative_error(lighting.extracted_power + lighting.residual_power, total), 1e-4f) << n;
        // SH band 0 is the residual's power: L00 * sqrt(4 pi).
        EXPECT_LT(max_relative_error(lighting.residual_sh[0] * std::sqrt(4.f * kPi), lighting.residual_power), 1e-4f);
    }
    // Most powerful first, and n = 0 extracts nothing.
    const EnvironmentLighting sixteen = map.split(16);
    ASSERT_GE(sixteen.lights.size(), 2u);
    auto lum = [](const Color& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; };
    for (size_t k = 1; k < sixteen.lights.size(); ++k)
        EXPECT_GE(lum(sixteen.lights[k - 1].intensity), lum(sixteen.lights[k].intensity));
    EXPECT_TRUE(map.split(0).lights.empty());
    EXPECT_TRUE(std::isinf(map.split(0).threshold));
    // The same threshold for every light count: 1/16 of the mean (the map's dimmest texel is darker).
    EXPECT_NEAR(sixteen.threshold, kExtractionThresholdFactor * lum(map.mean()), 1e-5f * sixteen.threshold);
    EXPECT_FLOAT_EQ(map.split(256).threshold, sixteen.threshold);
}

// ---- a sun -------------------------------------------------------------------------------------

TEST(Environment, SunBecomesOneLight) {
    const EnvironmentMap map(sun_environment(), 1);
    // The sun's power and its solid-angle centroid, summed over its 4 texels.
    double power = 0;
    Vec3f centroid(0.f);
    for (int y = kSunY; y < kSunY + 2; ++y)
        for (int x = kSunX; x < kSunX + 2; ++x) {
            power += kSun * texel_sr(y, kSunW, kSunH);
            centroid += texel_dir(x, y, kSunW, kSunH) * float(texel_sr(y, kSunW, kSunH));
        }
    const EnvironmentLighting lighting = map.split(1);
    ASSERT_EQ(lighting.lights.size(), 1u);
    const ExtractedLight& sun = lighting.lights[0];
    const float texel = kPi / kSunH;
    EXPECT_LT(angle_between(sun.direction, centroid), texel);
    EXPECT_NEAR(sun.intensity.y * kPi, power, 0.01 * power);
    EXPECT_FLOAT_EQ(sun.intensity.x, sun.intensity.z);  // white stays white
    // Almost nothing is left as ambient.
    EXPECT_LT(lighting.residual_power.y, 1e-3 * power);
    for (const Vec3f& n : axes()) EXPECT_LT(lighting.residual_irradiance(n).y, 1e-3 * power / kPi);
    // More lights do not invent light: the sun stays within a few regions, all near it.
    const EnvironmentLighting many = map.split(16);
    ASSERT_GE(many.lights.size(), 1u);
    EXPECT_LE(many.lights.size(), 4u);
    for (const ExtractedLight& l : many.lights) EXPECT_LT(angle_between(l.direction, centroid), 2.f * texel);
}

// The residual the lights leave: the sun capped at the threshold's luminance, with its own
// pyramid and prefilter; camera rays still see the whole sun. Nothing extracted: one pyramid.
TEST(Environment, ResidualIsWhatTheLightsLeave) {
    Environment env = sun_environment();
    const EnvironmentMap full(env, 1);
    EXPECT_FALSE(full.has_residual());
    const EnvironmentLighting lighting = full.split(1);
    env.extraction_threshold = lighting.threshold;
    const EnvironmentMap map(env, 1);
    ASSERT_TRUE(map.has_residual());
    const Vec3f sun = texel_dir(kSunX, kSunY, kSunW, kSunH);
    const float texel = float(kPi) / kSunH;  // a cone of one texel reads level 0
    EXPECT_EQ(map.radiance(sun, texel), full.radiance(sun, texel));
    EXPECT_GT(map.radiance(sun, texel).y, 0.2f * kSun);
    EXPECT_LE(map.residual_radiance(sun, texel).y, lighting.threshold * 1.0001f);
    EXPECT_GT(map.residual_radiance(sun, texel).y, 0.f);
    // The residual's power is what split() left, and its prefilter holds only that.
    EXPECT_LT(map.residual_prefiltered(sun, 0.5f).y, 1e-3f * map.prefiltered(sun, 0.5f).y);
    EXPECT_GT(map.bytes(), full.bytes());
    EXPECT_LE(map.bytes(), EnvironmentMap::estimated_bytes(map.width(), map.height()));
    // Without a texel above the threshold the residual is the map, stored once.
    Environment uniform = constant_environment(Color(0.5f));
    uniform.extraction_threshold = 0.9f;
    const EnvironmentMap same(uniform, 1);
    EXPECT_FALSE(same.has_residual());
    EXPECT_EQ(same.bytes(), EnvironmentMap(constant_environment(Color(0.5f)), 1).bytes());
    EXPECT_EQ(same.residual_prefiltered(sun, 0.7f), same.prefiltered(sun, 0.7f));
}

// ---- rotation ----------------------------------------------------------------------------------

TEST(Environment, RotationTurnsLightsAndLookups) {
    const Environment original = bundled("courtyard");
    Environment turned = original;
    turned.rotation_deg = 90.f;
    const EnvironmentMap a(original, 1), b(turned, 1);
    const EnvironmentLighting la = a.split(16), lb = b.split(16);
    ASSERT_EQ(la.lights.size(), lb.lights.size());
    ASSERT_GE(la.lights.size(), 4u);
    for (size_t k = 0; k < la.lights.size(); ++k) {
        const Vec3f want = rotate_y(la.lights[k].direction, 90.f);
        EXPECT_LT(angle_between(lb.lights[k].direction, want), 1e-4f) << k;
        EXPECT_LT(max_relative_error(lb.lights[k].intensity, la.lights[k].intensity), 1e-5f);
    }
    for (const Vec3f& d : random_directions(200, 11)) {
        const Vec3f back = rotate_y(d, -90.f);  // R^-1 d
        EXPECT_LT(max_relative_error(b.radiance(d), a.radiance(back)), 1e-4f);
        EXPECT_LT(max_relative_error(b.radiance(d, 0.2f), a.radiance(back, 0.2f)), 1e-4f);
        EXPECT_LT(max_relative_error(b.prefiltered(d, 0.6f), a.prefiltered(back, 0.6f)), 1e-4f);
        EXPECT_LT(max_relative_error(lb.residual_irradiance(d), la.residual_irradiance(back)), 1e-3f);
    }
    // The convention: +90 degrees brings the map's centre (+X) to -Z.
    EXPECT_LT(max_relative_error(b.radiance({0, 0, -1}), a.radiance({1, 0, 0})), 1e-5f);
    EXPECT_LT(max_relative_error(a.radiance({1, 0, 0}), a.radiance(latlong_direction(0.5f, 0.5f))), 1e-6f);
}

TEST(Environment, AxisConvention) {
    // Column u = 0.5 looks toward +X, u = 0.25 toward -Z, u = 0.75 toward +Z; row 0 is +Y.
    const float e = 1e-6f;
    EXPECT_NEAR(latlong_uv({1, 0, 0}).x, 0.5f, e);
    EXPECT_NEAR(latlong_uv({0, 0, -1}).x, 0.25f, e);
    EXPECT_NEAR(latlong_uv({0, 0, 1}).x, 0.75f, e);
    EXPECT_NEAR(latlong_uv({0, 1, 0}).y, 0.f, e);
    EXPECT_NEAR(latlong_uv({0, -1, 0}).y, 1.f, e);
    for (const Vec3f& d : random_directions(100, 3)) {
        const Vec2f uv = latlong_uv(d);
        EXPECT_LT(angle_between(latlong_direction(uv.x, uv.y), d), 1e-3f);
    }
}

// ---- the bundled maps' irradiance ------------------------------------------------------------

TEST(Environment, LightsPlusResidualReproduceIrradiance) {
    // Worst relative error over the colour channels at the 6 axis normals (the requirement) and
    // RMS over 50 random normals, with and without the ambient's correction of the lights.
    const std::vector<Vec3f> randoms = random_directions(50, 23);
    std::printf("[ irradiance ] map        n  lights  6 axes: worst %%  (uncorrected)   random normals: rms %%\n");
    for (const std::string name : {"studio", "courtyard"}) {
        const EnvironmentMap map(bundled(name), 1);
        std::vector<Color> reference, random_reference;
        for (const Vec3f& n : axes()) reference.push_back(map.brute_force_irradiance(n));
        for (const Vec3f& n : randoms) random_reference.push_back(map.brute_force_irradiance(n));
        for (int n_lights : {0, 1, 4, 16, 64, 128, 256}) {
            SplitSettings settings;
            settings.lights = n_lights;
            const EnvironmentLighting lighting = map.split(settings);
            settings.correct_ambient = false;
            const EnvironmentLighting plain = map.split(settings);
            float worst = 0.f, worst_plain = 0.f;
            for (size_t i = 0; i < axes().size(); ++i) {
                worst = std::max(worst, max_relative_error(lighting.irradiance(axes()[i]), reference[i]));
                worst_plain = std::max(worst_plain, max_relative_error(plain.irradiance(axes()[i]), reference[i]));
            }
            double squares = 0;
            for (size_t i = 0; i < randoms.size(); ++i) {
                const Color e = lighting.irradiance(randoms[i]);
                for (int c = 0; c < 3; ++c) squares += std::pow((e[c] - random_reference[i][c]) / random_reference[i][c], 2.0);
            }
            std::printf("[ irradiance ] %-9s %4d  %6zu  %8.2f  (%8.2f)  %12.2f\n", name.c_str(), n_lights,
                        lighting.lights.size(), 100.0 * worst, 100.0 * worst_plain,
                        100.0 * std::sqrt(squares / (3.0 * double(randoms.size()))));
            // The requirement, at the default count (the one `whitted bench env` chose): 2 % at the axes.
            if (n_lights >= kDefaultEnvironmentLights) EXPECT_LT(worst, 0.02f) << name;
        }
    }
}

// ---- lookups: seam, poles, MIP -----------------------------------------------------------------

TEST(Environment, SeamAndPolesAreContinuous) {
    const Environment env = bundled("courtyard");
    const EnvironmentMap map(env, 1);
    const EnvironmentImage& img = *env.image;
    // Across the wrap seam (u = 0 = 1, the -X direction): no jump beyond the texels' own step.
    for (int y = 8; y < img.height - 8; y += 16) {
        const float v = (y + 0.5f) / float(img.height);
        const Color left = map.radiance(latlong_direction(1.f - 1e-5f, v));
        const Color right = map.radiance(latlong_direction(1e-5f, v));
        const Color step = img.at(0, y) - img.at(img.width - 1, y);
        // The two points are 2e-5 of a turn apart: a continuous lookup moves by ~2 % of the step
        // between the seam's texels, one that clamps instead of wrapping jumps by all of it.
        const float allowed = 0.05f * max_abs(step) + 1e-6f * std::max(1.f, max_component(left));
        EXPECT_LE(max_abs(left - right), allowed) << "row " << y;
        // And the value there lies between the two texels it blends.
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(left[c], std::min(img.at(0, y)[c], img.at(img.width - 1, y)[c]) * 0.999f);
            EXPECT_LE(left[c], std::max(img.at(0, y)[c], img.at(img.width - 1, y)[c]) * 1.001f);
        }
    }
    // At a pole every longitude converges to the same value, and the poles are finite.
    for (const float pole : {1.f, -1.f}) {
        const Color at_pole = map.radiance({0, pole, 0});
        ASSERT_TRUE(is_finite(at_pole));
        const int row = pole > 0 ? 0 : img.height - 1;
        // eps from the pole the lookup is a share 2 eps h / pi of the way from the pole's value to
        // the pole row's (the blend over the last half texel): it converges, whatever the longitude.
        float spread = 0.f;  // largest difference between the pole row and the pole's value
        for (int x = 0; x < img.width; ++x) spread = std::max(spread, max_abs(img.at(x, row) - at_pole));
        for (int k = 0; k < 64; ++k) {
            const float phi = 2.f * kPi * k / 64.f, eps = 1e-4f;
            const Color near = map.radiance(normalize(Vec3f(eps * std::cos(phi), pole, eps * std::sin(phi))));
            const float share = 2.f * eps * float(img.height) / kPi;
            EXPECT_LE(max_abs(near - at_pole), std::max(1.1f * share * spread, 1e-6f)) << k;
        }
    }
    // No NaN anywhere: random directions, the axes, unnormalized and degenerate input.
    std::vector<Vec3f> dirs = random_directions(20000, 5);
    for (const Vec3f& a : axes()) dirs.push_back(a), dirs.push_back(a * 1e-20f), dirs.push_back(a * 1e20f);
    dirs.push_back(Vec3f(0.f));
    dirs.push_back({-1.f, 0.f, -0.f});
    dirs.push_back({-1.f, 0.f, 0.f});
    for (const Vec3f& d : dirs)
        for (const float cone : {0.f, 1e-3f, 0.1f, 3.f, kInfinity}) {
            ASSERT_TRUE(is_finite(map.radiance(d, cone))) << d.x << " " << d.y << " " << d.z;
            ASSERT_TRUE(is_finite(map.prefiltered(d, cone / 3.f)));
        }
    EXPECT_EQ(map.radiance({std::nanf(""), 0, 1}), Color(0.f));
}

TEST(Environment, MipLevelFollowsTheCone) {
    const EnvironmentMap map(bundled("studio"), 1);
    EXPECT_EQ(map.level_count(), 11);  // 1024 x 512 ... 2 x 1, 1 x 1
    // A cone wider than the whole map reads the coarsest level: the solid-angle mean.
    for (const Vec3f& d : random_directions(50, 9)) {
        EXPECT_LT(max_relative_error(map.radiance(d, 2.f * kPi), map.mean()), 0.01f);
        EXPECT_LT(max_relative_error(map.radiance(d, 1e3f), map.mean()), 0.01f);
    }
    // A cone up to one texel reads level 0; wider ones blur (the studio's softbox peak drops).
    const float texel = 2.f * kPi / float(map.width());
    Vec3f brightest{0, 1, 0};
    float peak = 0.f;
    for (const Vec3f& d : random_directions(20000, 13))
        if (map.radiance(d).y > peak) peak = map.radiance(d).y, brightest = d;
    EXPECT_EQ(map.radiance(brightest, 0.5f * texel), map.radiance(brightest));
    EXPECT_EQ(map.radiance(brightest, texel), map.radiance(brightest));
    EXPECT_LT(map.radiance(brightest, 64.f * texel).y, map.radiance(brightest, 4.f * texel).y);
    EXPECT_LE(map.radiance(brightest, 4.f * texel).y, peak);
}

// ---- prefiltered rough reflection --------------------------------------------------------------

TEST(Environment, PrefilteredConstantMapIsTheConstant) {
    const Color L{0.25f, 1.f, 3.f};
    const EnvironmentMap map(constant_environment(L), 1);
    for (const Vec3f& d : random_directions(200, 17))
        for (float r : {0.f, 0.1f, 0.25f, 0.4f, 0.75f, 1.f}) EXPECT_LT(max_relative_error(map.prefiltered(d, r), L), 1e-4f) << r;
}

TEST(Environment, PrefilteredSunSpreadsWithRoughness) {
    const EnvironmentMap map(sun_environment(), 1);
    const Vec3f sun = normalize(texel_dir(kSunX, kSunY, kSunW, kSunH) + texel_dir(kSunX + 1, kSunY + 1, kSunW, kSunH));
    // Half-maximum angle of the lobe along a great circle away from the sun.
    Vec3f side = normalize(cross(sun, Vec3f(0, 1, 0)));
    auto half_width = [&](float roughness) {
        const float peak = map.prefiltered(sun, roughness).y;
        for (int k = 1; k <= 900; ++k) {
            const float a = k * 0.1f * kPi / 180.f;
            if (map.prefiltered(sun * std::cos(a) + side * std::sin(a), roughness).y < 0.5f * peak) return a;
        }
        return kPi;
    };
    const float narrow = half_width(0.25f), mid = half_width(0.5f), wide = half_width(1.f);
    std::printf("[ prefilter ] half-maximum angles: roughness 0.25 %.1f deg, 0.5 %.1f deg, 1 %.1f deg\n",
                narrow * 180.f / kPi, mid * 180.f / kPi, wide * 180.f / kPi);
    EXPECT_LT(narrow, mid);
    EXPECT_LT(mid, wide);
    EXPECT_GT(map.prefiltered(sun, 0.25f).y, map.prefiltered(sun, 1.f).y);
    // The lobe points at the sun, and the roughest level still sees it from 60 degrees off.
    EXPECT_GT(map.prefiltered(sun, 0.25f).y, map.prefiltered(normalize(sun + side * 0.2f), 0.25f).y);
    const float off = 60.f * kPi / 180.f;
    EXPECT_GT(map.prefiltered(sun * std::cos(off) + side * std::sin(off), 1.f).y, 0.f);
}

TEST(Environment, PrefilterKeepsASymmetryAboutThePole) {
    // A map that depends on latitude alone (bands of sky, horizon and ground) prefilters to one
    // that does too: every texel of a row reads its row's sample pattern turned about the pole
    // (the frame's tangent follows longitude), so only longitude changes between texels and the
    // prefiltered rows are constant. What remains is the lookup's own rounding (its latitude from
    // the direction, to the last bit); a pattern turned differently at each texel (an arbitrary
    // tangent, as before) gave 5.6e-3.
    const EnvironmentMap map(make_environment(256, 128,
                                              [](int, int y) {
                                                  const float v = float(y) / 128.f;
                                                  return Color(4.f * v * v, v < 0.5f ? 2.f : 0.1f, 0.3f + v);
                                              }),
                             1);
    float worst = 0.f;
    for (float y : {0.95f, 0.5f, 0.1f, -0.3f, -0.9f}) {
        const float s = std::sqrt(1.f - y * y);
        for (float r : {0.3f, 0.5f, 0.75f, 1.f}) {
            const Color first = map.prefiltered({s, y, 0.f}, r);
            for (int k = 1; k < 16; ++k) {
                const float phi = 0.39f * float(k);
                worst = std::max(worst, max_relative_error(map.prefiltered({s * std::cos(phi), y, s * std::sin(phi)}, r), first));
            }
        }
    }
    std::printf("[ prefilter ] largest relative change along a latitude: %.2g\n", worst);
    EXPECT_LT(worst, 1e-5f);
}

TEST(Environment, SameResultForAnyThreadCount) {
    const Environment env = bundled("sunset");
    const EnvironmentMap one(env, 1), two(env, 2);
    for (const Vec3f& d : random_directions(500, 19))
        for (float r : {0.3f, 0.5f, 0.9f}) ASSERT_EQ(one.prefiltered(d, r), two.prefiltered(d, r));
}

// A render builds only the prefiltered levels its materials read: each roughness range reads
// exactly the levels prefilter_levels_read names, with the same values as a map holding all
// of them (bit for bit), and reading a level left out is an error, never a black reflection.
TEST(Environment, OnlyTheLevelsTheRoughnessReadsAreBuilt) {
    EXPECT_EQ(prefilter_levels_read(0.f, 0.f), 0b0001u);
    EXPECT_EQ(prefilter_levels_read(0.25f, 0.25f), 0b0001u);
    EXPECT_EQ(prefilter_levels_read(0.3f, 0.3f), 0b0011u);
    EXPECT_EQ(prefilter_levels_read(1.f, 1.f), 0b1100u);
    EXPECT_EQ(prefilter_levels_read(0.f, 1.f), kAllPrefilterLevels);
    EXPECT_EQ(prefilter_levels_read(0.6f, 0.4f), 0b0111u);
    EXPECT_EQ(prefilter_levels_read(std::nanf(""), std::nanf("")), 0b1100u);
    const Environment env = bundled("sunset");
    const EnvironmentMap all(env, 2);
    for (float r : {0.f, 0.1f, 0.25f, 0.4f, 0.5f, 0.7f, 0.9f, 1.f}) {
        const uint32_t levels = prefilter_levels_read(r, r);
        const EnvironmentMap some(env, 2, EnvironmentMap::Use::Rendering, levels);
        EXPECT_LT(some.bytes(), all.bytes()) << r;
        for (const Vec3f& d : random_directions(200, 5)) {
            ASSERT_EQ(some.prefiltered(d, r), all.prefiltered(d, r)) << r;
            ASSERT_EQ(some.residual_prefiltered(d, r), all.residual_prefiltered(d, r)) << r;
        }
        const float other = r <= 0.5f ? 1.f : 0.f;  // reads levels this map lacks
        EXPECT_THROW(some.prefiltered(random_directions(1, 1)[0], other), Error) << r;
    }
}

// The memory a built map reports stays within the estimate that --max-memory is checked against
// (the build and split times are figures of docs/measurements/environment.md, not asserted).
TEST(Environment, MemoryWithinEstimate) {
    const EnvironmentMap map(bundled("city"), 1);
    EXPECT_LE(map.bytes(), EnvironmentMap::estimated_bytes(map.width(), map.height()));
    EXPECT_GT(map.bytes(), size_t(1024 * 512 * 12));
}

TEST(Environment, ExtractedLightAsDirectionalLight) {
    ExtractedLight e;
    e.direction = normalize(Vec3f(1, 2, 3));
    e.intensity = {2.f, 4.f, 1.f};
    const Light l = to_directional_light(e, "environment light 0");
    EXPECT_EQ(l.type, LightType::Directional);
    EXPECT_EQ(l.attenuation, Attenuation::None);
    EXPECT_FLOAT_EQ(l.intensity, 4.f);
    EXPECT_FLOAT_EQ(l.color.x * l.intensity, 2.f);
    EXPECT_FLOAT_EQ(l.color.z * l.intensity, 1.f);
    EXPECT_NEAR(l.direction.x, -e.direction.x, 1e-7);
    EXPECT_NEAR(l.direction.z, -e.direction.z, 1e-7);
}

// ---- loading -----------------------------------------------------------------------------------

class EnvironmentLoad : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() / fmt::format("whitted_test_environment_{}_{}", long(::getpid()), info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    /// Writes a w x h image of `channels` float channels (or 8-bit when `format` says so).
    std::string write(const std::string& name, int w, int h, int channels, const std::vector<float>& values,
                      OIIO::TypeDesc format = OIIO::TypeDesc::FLOAT) const {
        const std::string p = path(name);
        auto out = OIIO::ImageOutput::create(p);
        EXPECT_TRUE(out) << OIIO::geterror();
        OIIO::ImageSpec spec(w, h, channels, format);
        EXPECT_TRUE(out->open(p, spec)) << out->geterror();
        EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data())) << out->geterror();
        out->close();
        return p;
    }
    /// The one-line message of the error loading `file` throws (fails when it does not throw).
    std::string error_of(const std::string& file, size_t max_memory = size_t(1) << 30) const {
        std::vector<std::string> warnings;
        try {
            load_environment_image(file, max_memory, warnings);
        } catch (const Error& e) {
            return e.what();
        }
        ADD_FAILURE() << file << " loaded";
        return {};
    }
    fs::path m_dir;
};

TEST_F(EnvironmentLoad, Errors) {
    const std::string missing = path("missing.exr");
    std::string e = error_of(missing);
    EXPECT_NE(e.find(missing), std::string::npos) << e;
    EXPECT_NE(e.find("no such file"), std::string::npos) << e;

    const std::string text = path("notes.exr");
    std::ofstream(text) << "this is not an image\n";
    e = error_of(text);
    EXPECT_NE(e.find(text), std::string::npos) << e;
    EXPECT_NE(e.find("not an image"), std::string::npos) << e;

    // A 0 x 0 image that OpenImageIO opens (a PPM header with no pixels).
    const std::string empty = path("empty.ppm");
    std::ofstream(empty) << "P6\n0 0\n255\n";
    e = error_of(empty);
    EXPECT_NE(e.find(empty), std::string::npos) << e;
    EXPECT_NE(e.find("empty (0x0"), std::string::npos) << e;

    const std::string dir = path("folder.exr");
    fs::create_directories(dir);
    EXPECT_NE(error_of(dir).find("not a file"), std::string::npos);

    // Too big for the memory limit.
    const std::string small = write("small.exr", 16, 8, 3, std::vector<float>(16 * 8 * 3, 1.f));
    e = error_of(small, 1024);
    EXPECT_NE(e.find("--max-memory"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    std::vector<std::string> warnings;
    EXPECT_NO_THROW(load_environment_image(small, environment_load_bytes(16, 8, 3), warnings));
    EXPECT_TRUE(warnings.empty());
}

TEST_F(EnvironmentLoad, AspectWarns) {
    std::vector<std::string> warnings;
    const EnvironmentImage img = load_environment_image(write("square.exr", 8, 8, 3, std::vector<float>(8 * 8 * 3, 0.5f)), size_t(1) << 30, warnings);
    EXPECT_EQ(img.width, 8);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("not 2:1"), std::string::npos) << warnings[0];
    EXPECT_EQ(img.name, "square");
}

TEST_F(EnvironmentLoad, BadTexelsClampWithOneWarning) {
    std::vector<float> v(8 * 4 * 3, 2.f);
    v[0] = std::nanf("");                   // texel 0
    v[4] = -1.f, v[5] = std::nanf("");       // texel 1 (two bad channels: one texel)
    v[9] = std::numeric_limits<float>::infinity();  // texel 3
    v[14] = -0.003f;                         // texel 4
    v[20] = -std::numeric_limits<float>::infinity();  // texel 6
    std::vector<std::string> warnings;
    const EnvironmentImage img = load_environment_image(write("bad.exr", 8, 4, 3, v), size_t(1) << 30, warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("5 texels"), std::string::npos) << warnings[0];
    for (const Color& c : img.texels) {
        EXPECT_TRUE(is_finite(c));
        EXPECT_GE(std::min({c.x, c.y, c.z}), 0.f);
    }
    EXPECT_EQ(img.texels[0], Color(0.f, 2.f, 2.f));
    EXPECT_EQ(img.texels[1], Color(2.f, 0.f, 0.f));
    EXPECT_EQ(img.texels[2], Color(2.f));
    EXPECT_EQ(img.texels[4], Color(2.f, 2.f, 0.f));
}

TEST_F(EnvironmentLoad, GreyAndSrgb) {
    std::vector<std::string> warnings;
    // One channel: grey -> RGB; float data stays linear.
    const EnvironmentImage grey = load_environment_image(write("grey.exr", 4, 2, 1, std::vector<float>(8, 0.3f)), size_t(1) << 30, warnings);
    EXPECT_EQ(grey.texels[5], Color(0.3f));
    // An 8-bit PNG is sRGB: code 128 is 0.2158605 linear.
    const EnvironmentImage png = load_environment_image(
        write("srgb.png", 4, 2, 3, std::vector<float>(24, 128.f / 255.f), OIIO::TypeDesc::UINT8), size_t(1) << 30, warnings);
    EXPECT_NEAR(png.texels[3].y, 0.2158605f, 1e-5f);
    EXPECT_TRUE(warnings.empty());
}

TEST_F(EnvironmentLoad, BundledNames) {
    for (const std::string& name : bundled_environment_names()) {
        const std::string p = resolve_environment_name(name);
        EXPECT_TRUE(fs::exists(p)) << p;
        EXPECT_NE(p.find("assets/environments/" + name + ".exr"), std::string::npos) << p;
        std::vector<std::string> warnings;
        const EnvironmentImage img = load_environment_image(p, size_t(1) << 30, warnings);
        EXPECT_EQ(img.width, name == "furnace" ? 64 : 1024);  // the furnace: a uniform 1, 64 x 32
        EXPECT_EQ(img.height, name == "furnace" ? 32 : 512);
        if (name == "furnace")
            for (const Color& t : img.texels) ASSERT_EQ(t, Color(1.f));
        EXPECT_EQ(img.name, name);
        EXPECT_LE(warnings.size(), 1u);  // at most the clamp of the maps' slightly negative texels
    }
    EXPECT_EQ(bundled_environment_names().front(), "studio");
    // A path that exists is used as is; an unknown name lists the bundled ones.
    const std::string file = write("mine.exr", 8, 4, 3, std::vector<float>(96, 1.f));
    EXPECT_EQ(resolve_environment_name(file), file);
    try {
        resolve_environment_name("moonbase");
        ADD_FAILURE() << "unknown name resolved";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("moonbase"), std::string::npos) << m;
        EXPECT_NE(m.find("studio, city, courtyard, forest, interior, sunset"), std::string::npos) << m;
    }
}

}  // namespace
}  // namespace whitted
