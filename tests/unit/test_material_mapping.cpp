// glTF metallic-roughness -> Whitted coefficients: one test per row of docs/materials.md with
// hand-computed numbers, plus energy conservation over random inputs.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "shading/material_mapping.h"

namespace whitted {
namespace {

constexpr float kEps = 1e-6f;

#define EXPECT_COLOR_NEAR(actual, expected, eps)       \
    do {                                               \
        const Color a_ = (actual), e_ = (expected);    \
        EXPECT_NEAR(a_.x, e_.x, eps) << "red";         \
        EXPECT_NEAR(a_.y, e_.y, eps) << "green";       \
        EXPECT_NEAR(a_.z, e_.z, eps) << "blue";        \
    } while (0)

/// A glTF dielectric with the given base color and roughness (ior 1.5, no extensions).
Material dielectric(Color base, float roughness) {
    Material m;
    m.base_color = Vec4f(base, 1.f);
    m.metallic = 0.f;
    m.roughness = roughness;
    return m;
}

WhittedCoeffs map_constant(const Material& m, const MappingOptions& options = {}) {
    return map_material_constant(m, options);
}

TEST(MaterialMapping, IorToF0) {
    EXPECT_NEAR(ior_to_f0(1.5f), 0.04f, kEps);
    EXPECT_EQ(ior_to_f0(1.f), 0.f);
    EXPECT_NEAR(ior_to_f0(2.f), 1.f / 9.f, kEps);
    EXPECT_EQ(ior_to_f0(0.f), 1.f);  // KHR_materials_specular specular-glossiness conversion
    EXPECT_EQ(ior_to_f0(std::numeric_limits<float>::infinity()), 1.f);
    EXPECT_NEAR(ior_to_f0(std::nanf("")), 0.04f, kEps);
}

TEST(MaterialMapping, DielectricWhiteRough) {
    // F0 = 0.04; kd = 1 * (1 - 0.04); n = 2/1 - 2 = 0 -> clamped to 1; no mirror, no transmission.
    const WhittedCoeffs c = map_constant(dielectric(Color(1.f), 1.f));
    EXPECT_COLOR_NEAR(c.kd, Color(0.96f), kEps);
    EXPECT_COLOR_NEAR(c.ka, Color(0.96f), kEps);
    EXPECT_COLOR_NEAR(c.ks, Color(0.04f), kEps);
    EXPECT_EQ(c.n, 1.f);
    EXPECT_COLOR_NEAR(c.kr, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kt, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.emission, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.absorption, Color(0.f), 0.f);
    EXPECT_TRUE(c.thin);
    EXPECT_EQ(c.ior, 1.5f);
}

TEST(MaterialMapping, OcclusionScalesAmbientOnly) {
    PbrSample s = constant_pbr_sample(dielectric(Color(0.5f, 0.25f, 1.f), 1.f));
    s.occlusion = 0.5f;
    const WhittedCoeffs c = map_gltf_material(dielectric(Color(1.f), 1.f), s, {});
    // kd = base * 0.96, ka = kd * 0.5.
    EXPECT_COLOR_NEAR(c.kd, Color(0.48f, 0.24f, 0.96f), kEps);
    EXPECT_COLOR_NEAR(c.ka, Color(0.24f, 0.12f, 0.48f), kEps);
}

TEST(MaterialMapping, PureMetal) {
    Material m;
    m.base_color = {0.9f, 0.6f, 0.2f, 1.f};
    m.metallic = 1.f;
    m.roughness = 0.5f;
    const WhittedCoeffs c = map_constant(m);
    // F0 = baseColor; alpha = 0.25 -> n = 2/0.0625 - 2 = 30; roughness 0.5 >= cutoff 0.3 -> kr = 0.
    EXPECT_COLOR_NEAR(c.kd, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.ka, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.ks, Color(0.9f, 0.6f, 0.2f), kEps);
    EXPECT_NEAR(c.n, 30.f, 1e-3f);
    EXPECT_COLOR_NEAR(c.kr, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kt, Color(0.f), 0.f);
}

TEST(MaterialMapping, HalfMetallicMixesF0AndDiffuse) {
    Material m = dielectric(Color(1.f), 0.f);
    m.metallic = 0.5f;
    const WhittedCoeffs c = map_constant(m);
    // F0 = 0.5 * 0.04 + 0.5 * 1 = 0.52; kd = 0.5 * 0.96 = 0.48; kd + kr = 1 exactly.
    EXPECT_COLOR_NEAR(c.ks, Color(0.52f), kEps);
    EXPECT_COLOR_NEAR(c.kr, Color(0.52f), kEps);
    EXPECT_COLOR_NEAR(c.kd, Color(0.48f), kEps);
}

TEST(MaterialMapping, MetalsDoNotTransmit) {
    Material m = dielectric(Color(0.8f), 0.f);
    m.metallic = 1.f;
    m.transmission = 1.f;
    const WhittedCoeffs c = map_constant(m);
    EXPECT_COLOR_NEAR(c.kt, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kd, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.ks, Color(0.8f), kEps);
}

TEST(MaterialMapping, RoughnessZeroIsMirrorWithFiniteExponent) {
    Material m;
    m.base_color = {0.9f, 0.6f, 0.2f, 1.f};
    m.metallic = 1.f;
    m.roughness = 0.f;
    const WhittedCoeffs c = map_constant(m);
    EXPECT_COLOR_NEAR(c.kr, Color(0.9f, 0.6f, 0.2f), kEps);
    EXPECT_TRUE(std::isfinite(c.n));
    EXPECT_EQ(c.n, 10000.f);  // options.max_exponent

    // Without the clamp the exponent is still finite: alpha floor 1e-3 -> 2/1e-6 - 2.
    MappingOptions unclamped;
    unclamped.max_exponent = std::numeric_limits<float>::max();
    const WhittedCoeffs u = map_constant(m, unclamped);
    EXPECT_TRUE(std::isfinite(u.n));
    EXPECT_NEAR(u.n, 2e6f - 2.f, 1.f);
}

TEST(MaterialMapping, MirrorFadesToZeroAtCutoff) {
    Material m = dielectric(Color(1.f), 0.f);
    MappingOptions options;  // cutoff 0.3

    EXPECT_COLOR_NEAR(map_constant(m, options).kr, Color(0.04f), kEps);
    // Half way: 1 - smoothstep(0.5) = 0.5.
    m.roughness = 0.15f;
    EXPECT_COLOR_NEAR(map_constant(m, options).kr, Color(0.02f), kEps);
    // A quarter of the way: 1 - (3 * 0.25^2 - 2 * 0.25^3) = 0.84375.
    m.roughness = 0.075f;
    EXPECT_COLOR_NEAR(map_constant(m, options).kr, Color(0.04f * 0.84375f), kEps);
    // Just below the cutoff still reflects a little; at and above it nothing.
    m.roughness = 0.29f;
    EXPECT_GT(map_constant(m, options).kr.x, 0.f);
    m.roughness = 0.3f;
    EXPECT_COLOR_NEAR(map_constant(m, options).kr, Color(0.f), 0.f);
    m.roughness = 0.8f;
    EXPECT_COLOR_NEAR(map_constant(m, options).kr, Color(0.f), 0.f);

    // The fade is monotonic and flat at 0.
    EXPECT_EQ(mirror_fade(0.f, 0.3f), 1.f);
    float previous = 1.f;
    for (int i = 1; i <= 40; ++i) {
        const float f = mirror_fade(float(i) * 0.01f, 0.3f);
        EXPECT_LE(f, previous);
        previous = f;
    }
    // A cutoff of 0 disables the mirror term entirely.
    EXPECT_EQ(mirror_fade(0.f, 0.f), 0.f);
}

// What the mirror term gives up on rough surfaces is the glossy weight: kr + kg = F0 = ks at
// every roughness, for metals and dielectrics; classic materials have no glossy term.
TEST(MaterialMapping, GlossyTakesWhatTheMirrorGivesUp) {
    for (const Material& base : {dielectric(Color(0.8f, 0.5f, 0.2f), 0.f), [] {
             Material metal;
             metal.base_color = {0.9f, 0.6f, 0.3f, 1.f};
             metal.metallic = 1.f;
             return metal;
         }()}) {
        for (int i = 0; i <= 20; ++i) {
            Material m = base;
            m.roughness = float(i) * 0.05f;
            const WhittedCoeffs c = map_constant(m);
            SCOPED_TRACE(testing::Message() << "metallic " << m.metallic << " roughness " << m.roughness);
            EXPECT_COLOR_NEAR(c.kr + c.kg, c.ks, kEps);
            EXPECT_EQ(c.roughness, m.roughness);
            if (m.roughness >= 0.3f) EXPECT_COLOR_NEAR(c.kg, c.ks, 0.f);
            if (m.roughness == 0.f) EXPECT_COLOR_NEAR(c.kg, Color(0.f), 0.f);
        }
    }
    Material metal = dielectric(Color(0.9f, 0.6f, 0.3f), 1.f);
    metal.metallic = 1.f;
    EXPECT_COLOR_NEAR(map_constant(metal).kg, Color(0.9f, 0.6f, 0.3f), kEps);  // f0 = base colour
    Material classic;
    classic.model = MaterialModel::Classic;
    classic.classic.kr = Color(0.5f);
    EXPECT_COLOR_NEAR(map_constant(classic).kg, Color(0.f), 0.f);
}

TEST(MaterialMapping, RoughSceneNeverRecurses) {
    // Every material at or above the cutoff has kr = 0 whatever its other inputs.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    for (int i = 0; i < 1000; ++i) {
        Material m = dielectric(Color(unit(rng), unit(rng), unit(rng)), 0.3f + 0.7f * unit(rng));
        m.metallic = unit(rng);
        m.transmission = unit(rng);
        EXPECT_TRUE(is_black(map_constant(m).kr));
    }
}

TEST(MaterialMapping, TransmissiveThin) {
    Material m = dielectric(Color(1.f, 0.5f, 0.25f), 0.f);
    m.transmission = 1.f;
    const WhittedCoeffs c = map_constant(m);
    // kd = 0; kt = 1 * (1 - 0.04) * baseColor; no volume -> thin, no absorption.
    EXPECT_COLOR_NEAR(c.kd, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kt, Color(0.96f, 0.48f, 0.24f), kEps);
    EXPECT_COLOR_NEAR(c.ks, Color(0.04f), kEps);
    EXPECT_COLOR_NEAR(c.kr, Color(0.04f), kEps);
    EXPECT_TRUE(c.thin);
    EXPECT_COLOR_NEAR(c.absorption, Color(0.f), 0.f);

    // Half transmissive: the energy under the specular layer is split evenly.
    m.transmission = 0.5f;
    const WhittedCoeffs h = map_constant(m);
    EXPECT_COLOR_NEAR(h.kd, Color(0.48f, 0.24f, 0.12f), kEps);
    EXPECT_COLOR_NEAR(h.kt, Color(0.48f, 0.24f, 0.12f), kEps);
}

TEST(MaterialMapping, TransmissiveVolume) {
    Material m = dielectric(Color(1.f), 0.f);
    m.transmission = 1.f;
    m.ior = 1.33f;
    m.has_volume = true;
    m.thickness = 1.f;
    m.attenuation_color = {0.5f, 0.25f, 1.f};
    m.attenuation_distance = 2.f;
    const WhittedCoeffs c = map_constant(m);
    // Refracts by ior; sigma = -ln(color) / distance.
    EXPECT_FALSE(c.thin);
    EXPECT_EQ(c.ior, 1.33f);
    EXPECT_COLOR_NEAR(c.absorption, Color(std::log(2.f) / 2.f, std::log(4.f) / 2.f, 0.f), kEps);
    const float f0 = ior_to_f0(1.33f);
    EXPECT_COLOR_NEAR(c.kt, Color(1.f - f0), kEps);

    // Infinite distance: no absorption. Black attenuation: finite, large absorption.
    m.attenuation_distance = kInfinity;
    EXPECT_COLOR_NEAR(map_constant(m).absorption, Color(0.f), 0.f);
    m.attenuation_distance = 1.f;
    m.attenuation_color = Color(0.f);
    const Color black = map_constant(m).absorption;
    EXPECT_TRUE(is_finite(black));
    EXPECT_GT(black.x, 10.f);

    // has_volume with zero thickness is thin-walled (KHR_materials_volume: thickness 0 = thin).
    m.thickness = 0.f;
    EXPECT_TRUE(map_constant(m).thin);
    EXPECT_COLOR_NEAR(map_constant(m).absorption, Color(0.f), 0.f);
}

TEST(MaterialMapping, RefractThinOption) {
    Material m = dielectric(Color(1.f), 0.f);
    m.transmission = 1.f;
    MappingOptions options;
    options.refract_thin = true;
    const WhittedCoeffs c = map_constant(m, options);
    EXPECT_FALSE(c.thin);
    EXPECT_COLOR_NEAR(c.absorption, Color(0.f), 0.f);  // no volume, nothing absorbs

    // Opaque materials are untouched by the option.
    m.transmission = 0.f;
    EXPECT_TRUE(map_constant(m, options).thin);
}

TEST(MaterialMapping, SpecularExtensionChangesF0) {
    Material m = dielectric(Color(1.f), 1.f);
    m.specular = 0.5f;
    m.specular_color = {2.f, 1.f, 0.f};
    // F0d = min(0.04 * (2, 1, 0), 1) * 0.5 = (0.04, 0.02, 0); kd = 1 - max(F0d) = 0.96.
    WhittedCoeffs c = map_constant(m);
    EXPECT_COLOR_NEAR(c.ks, Color(0.04f, 0.02f, 0.f), kEps);
    EXPECT_COLOR_NEAR(c.kd, Color(0.96f), kEps);

    // specular = 0 removes the dielectric highlight and gives all energy to the diffuse.
    m.specular = 0.f;
    c = map_constant(m);
    EXPECT_COLOR_NEAR(c.ks, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kd, Color(1.f), kEps);

    // The product with the ior F0 is clamped to 1 before the specular weight.
    m.specular = 0.5f;
    m.specular_color = Color(50.f);
    c = map_constant(m);
    EXPECT_COLOR_NEAR(c.ks, Color(0.5f), kEps);
    EXPECT_COLOR_NEAR(c.kd, Color(0.5f), kEps);

    // Metals ignore the extension (F0 = baseColor).
    m.metallic = 1.f;
    m.base_color = {0.7f, 0.7f, 0.7f, 1.f};
    EXPECT_COLOR_NEAR(map_constant(m).ks, Color(0.7f), kEps);
}

TEST(MaterialMapping, IorOneGivesNoReflection) {
    Material m = dielectric(Color(0.5f), 0.f);
    m.ior = 1.f;
    m.transmission = 0.5f;
    const WhittedCoeffs c = map_constant(m);
    EXPECT_COLOR_NEAR(c.ks, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kr, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.kd, Color(0.25f), kEps);
    EXPECT_COLOR_NEAR(c.kt, Color(0.25f), kEps);
}

TEST(MaterialMapping, EnergyConservedForRandomInputs) {
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    std::uniform_real_distribution<float> wide(-0.5f, 3.f);  // includes out-of-range values
    for (int i = 0; i < 20000; ++i) {
        Material m;
        m.ior = 1.f + 2.f * unit(rng);
        m.has_volume = unit(rng) < 0.5f;
        m.thickness = unit(rng);
        m.attenuation_color = Color(unit(rng), unit(rng), unit(rng));
        m.attenuation_distance = 0.1f + 10.f * unit(rng);
        PbrSample s;
        s.base_color = {wide(rng), wide(rng), wide(rng), unit(rng)};
        s.metallic = wide(rng);
        s.roughness = wide(rng);
        s.transmission = wide(rng);
        s.occlusion = wide(rng);
        s.specular = wide(rng);
        s.specular_color = Color(wide(rng), wide(rng), wide(rng)) * 2.f;
        const WhittedCoeffs c = map_gltf_material(m, s, {});
        for (int ch = 0; ch < 3; ++ch) {
            SCOPED_TRACE(testing::Message() << "sample " << i << " channel " << ch);
            EXPECT_LE(c.ks[ch] + c.kt[ch], 1.f + kEps);
            EXPECT_LE(c.kd[ch] + c.kr[ch] + c.kg[ch] + c.kt[ch], 1.f + kEps);
            EXPECT_LE(c.ka[ch], c.kd[ch] + kEps);
            for (float v : {c.kd[ch], c.ka[ch], c.ks[ch], c.kr[ch], c.kt[ch], c.absorption[ch]}) {
                EXPECT_TRUE(std::isfinite(v));
                EXPECT_GE(v, 0.f);
            }
        }
        EXPECT_TRUE(std::isfinite(c.n));
        EXPECT_GE(c.n, 1.f);
        EXPECT_LE(c.n, 10000.f);
    }
}

TEST(MaterialMapping, NanInputsGiveFiniteCoefficients) {
    const float nan = std::nanf("");
    PbrSample s;
    s.base_color = {nan, 0.5f, nan, nan};
    s.metallic = nan;
    s.roughness = nan;
    s.transmission = nan;
    s.occlusion = nan;
    s.emissive = {nan, -1.f, kInfinity};
    s.specular = nan;
    s.specular_color = Color(nan);
    const WhittedCoeffs c = map_gltf_material(Material{}, s, {});
    for (const Color& v : {c.kd, c.ka, c.ks, c.kr, c.kt, c.emission, c.absorption}) EXPECT_TRUE(is_finite(v));
    EXPECT_TRUE(std::isfinite(c.n));
    EXPECT_COLOR_NEAR(c.emission, Color(0.f), 0.f);
}

TEST(MaterialMapping, EmissionIsTheSampleValue) {
    Material m = dielectric(Color(0.5f), 1.f);
    m.emissive = {1.f, 0.5f, 0.25f};
    m.emissive_strength = 4.f;
    // Constant sample: emissive * strength.
    EXPECT_COLOR_NEAR(map_constant(m).emission, Color(4.f, 2.f, 1.f), kEps);
    // Textured sample: whatever the caller computed, unchanged (and not clamped to 1).
    PbrSample s = constant_pbr_sample(m);
    s.emissive = {7.f, 0.f, 0.5f};
    EXPECT_COLOR_NEAR(map_gltf_material(m, s, {}).emission, Color(7.f, 0.f, 0.5f), 0.f);
}

TEST(MaterialMapping, Unlit) {
    Material m = dielectric(Color(0.2f, 0.4f, 0.6f), 0.f);
    m.unlit = true;
    m.metallic = 1.f;
    m.transmission = 1.f;
    m.emissive = Color(5.f);
    const WhittedCoeffs c = map_constant(m);
    EXPECT_COLOR_NEAR(c.emission, Color(0.2f, 0.4f, 0.6f), kEps);
    for (const Color& v : {c.kd, c.ka, c.ks, c.kr, c.kt, c.absorption}) EXPECT_COLOR_NEAR(v, Color(0.f), 0.f);
}

TEST(MaterialMapping, ClassicPassthrough) {
    Material m;
    m.model = MaterialModel::Classic;
    m.base_color = {0.f, 0.f, 0.f, 1.f};  // ignored
    m.classic.kd = {0.1f, 0.2f, 0.3f};
    m.classic.ka = {0.4f, 0.5f, 0.6f};
    m.classic.ks = {0.7f, 0.8f, 0.9f};
    m.classic.n = 42.f;
    m.classic.kr = Color(0.25f);
    m.classic.kt = Color(0.5f);
    m.classic.ior = 2.4f;
    m.classic.thin = false;
    m.classic.emission = Color(3.f);
    m.classic.absorption = Color(0.125f);
    PbrSample s;
    s.base_color = {1.f, 0.f, 0.f, 1.f};
    s.metallic = 0.f;
    const WhittedCoeffs c = map_gltf_material(m, s, {});
    EXPECT_EQ(c.kd, m.classic.kd);
    EXPECT_EQ(c.ka, m.classic.ka);
    EXPECT_EQ(c.ks, m.classic.ks);
    EXPECT_EQ(c.n, m.classic.n);
    EXPECT_EQ(c.kr, m.classic.kr);
    EXPECT_EQ(c.kt, m.classic.kt);
    EXPECT_EQ(c.ior, m.classic.ior);
    EXPECT_EQ(c.thin, m.classic.thin);
    EXPECT_EQ(c.emission, m.classic.emission);
    EXPECT_EQ(c.absorption, m.classic.absorption);
}

TEST(MaterialMapping, ConstantSampleUsesFactors) {
    Material m;
    m.base_color = {0.1f, 0.2f, 0.3f, 0.4f};
    m.metallic = 0.25f;
    m.roughness = 0.75f;
    m.transmission = 0.5f;
    m.emissive = Color(2.f);
    m.emissive_strength = 3.f;
    m.specular = 0.6f;
    m.specular_color = {1.f, 0.5f, 0.f};
    const PbrSample s = constant_pbr_sample(m);
    EXPECT_EQ(s.base_color, m.base_color);
    EXPECT_EQ(s.metallic, 0.25f);
    EXPECT_EQ(s.roughness, 0.75f);
    EXPECT_EQ(s.transmission, 0.5f);
    EXPECT_EQ(s.occlusion, 1.f);
    EXPECT_EQ(s.emissive, Color(6.f));
    EXPECT_EQ(s.specular, 0.6f);
    EXPECT_EQ(s.specular_color, m.specular_color);
}

TEST(MaterialMapping, GltfDefaultMaterialIsRoughWhiteMetal) {
    // glTF defaults: baseColor 1, metallic 1, roughness 1.
    const WhittedCoeffs c = map_constant(Material{});
    EXPECT_COLOR_NEAR(c.kd, Color(0.f), 0.f);
    EXPECT_COLOR_NEAR(c.ks, Color(1.f), kEps);
    EXPECT_COLOR_NEAR(c.kr, Color(0.f), 0.f);
    EXPECT_EQ(c.n, 1.f);
}

}  // namespace
}  // namespace whitted
