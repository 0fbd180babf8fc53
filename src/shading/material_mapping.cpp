// glTF metallic-roughness -> Whitted (1980) coefficients. The reasons for every row are in
// docs/materials.md; the formulas are summarised in material_mapping.h.
#include "shading/material_mapping.h"

#include <algorithm>
#include <cmath>

namespace whitted {

namespace {

/// Smallest GGX/Beckmann alpha used for the exponent, so n = 2/alpha^2 - 2 stays finite.
constexpr float kMinAlpha = 1e-3f;
/// Smallest attenuation color used for the Beer-Lambert coefficient, so -ln(c) stays finite.
constexpr float kMinAttenuationColor = 1e-6f;
/// F0 of the glTF default ior 1.5, used for invalid (negative or NaN) ior values.
constexpr float kDefaultF0 = 0.04f;

/// Clamp to [0, 1] with NaN -> 0.
inline float saturate(float x) { return x > 0.f ? (x < 1.f ? x : 1.f) : 0.f; }
inline Color saturate(const Color& c) { return {saturate(c.x), saturate(c.y), saturate(c.z)}; }

/// Finite and non-negative, anything else (negative, NaN, infinity) -> 0.
inline float finite_nonneg(float x) { return (x > 0.f && std::isfinite(x)) ? x : 0.f; }
inline Color finite_nonneg(const Color& c) { return {finite_nonneg(c.x), finite_nonneg(c.y), finite_nonneg(c.z)}; }

}  // namespace

float ior_to_f0(float ior) {
    // Both limits give total reflection at normal incidence; the KHR_materials_specular
    // specular-glossiness conversion relies on ior = 0 giving F0 = 1.
    if (std::isinf(ior)) return 1.f;
    if (!(ior >= 0.f)) return kDefaultF0;
    const float r = (ior - 1.f) / (ior + 1.f);
    return r * r;
}

float mirror_fade(float roughness, float cutoff) {
    if (!(cutoff > 0.f)) return 0.f;
    // 1 - smoothstep(0, cutoff, r): flat at r = 0 (polished surfaces stay mirrors) and meets 0
    // with zero slope at the cutoff (no visible seam where the mirror term switches off).
    const float x = saturate(roughness / cutoff);
    return 1.f - x * x * (3.f - 2.f * x);
}

PbrSample constant_pbr_sample(const Material& material) {
    PbrSample s;
    s.base_color = material.base_color;
    s.metallic = material.metallic;
    s.roughness = material.roughness;
    s.transmission = material.transmission;
    s.occlusion = 1.f;
    s.emissive = material.emissive * material.emissive_strength;
    s.specular = material.specular;
    s.specular_color = material.specular_color;
    return s;
}

WhittedCoeffs map_gltf_material(const Material& material, const PbrSample& sample, const MappingOptions& options) {
    // Scene-file materials carry Whitted's (1980) coefficients directly.
    if (material.model == MaterialModel::Classic) return material.classic;

    WhittedCoeffs c;
    c.ior = material.ior;
    const Color base = saturate(sample.base_color.xyz());

    // KHR_materials_unlit: the base color is shown as is, nothing reflects or transmits.
    if (material.unlit) {
        c.emission = base;
        return c;
    }

    const float metallic = saturate(sample.metallic);
    const float roughness = saturate(sample.roughness);
    const float transmission = saturate(sample.transmission);
    const float occlusion = saturate(sample.occlusion);

    // Normal-incidence Fresnel: dielectric F0 per KHR_materials_specular (ior, specular color
    // clamped to 1, then the specular weight), mixed towards the base color for metals.
    const Color f0_dielectric =
        vmin(finite_nonneg(sample.specular_color) * ior_to_f0(material.ior), Color(1.f)) * saturate(sample.specular);
    const Color f0 = lerp(f0_dielectric, base, metallic);

    // Energy left under the dielectric's specular layer (glTF fresnel_mix weights its base by
    // 1 - max_value(F)), shared between the diffuse and the transmitted part.
    const float dielectric_base = (1.f - metallic) * (1.f - max_component(f0_dielectric));
    c.kd = base * (dielectric_base * (1.f - transmission));
    c.ka = c.kd * occlusion;
    c.kt = base * (dielectric_base * transmission);

    // Highlight: Phong-Blinn exponent matching a Beckmann lobe of width alpha = roughness^2
    // (Walter et al. 2007), kept finite for perfectly smooth surfaces.
    c.ks = f0;
    const float alpha = std::max(roughness * roughness, kMinAlpha);
    const float max_exponent = std::max(1.f, options.max_exponent);
    c.n = std::clamp(2.f / (alpha * alpha) - 2.f, 1.f, max_exponent);

    // Mirror reflection only for smooth surfaces, faded out towards the cutoff; what the mirror
    // term gives up is the glossy weight (the environment prefiltered by roughness).
    const float fade = mirror_fade(roughness, options.mirror_roughness_cutoff);
    c.kr = f0 * fade;
    c.kg = f0 * (1.f - fade);
    c.roughness = roughness;

    // Thin-walled unless KHR_materials_volume gives the material an inside; --refract-thin
    // refracts every transmissive material (decided per material so all its points agree).
    const bool volume = material.has_volume && material.thickness > 0.f;
    const bool transmissive_material = material.transmission > 0.f;
    c.thin = !(volume || (options.refract_thin && transmissive_material));

    // Beer-Lambert coefficient: light keeps attenuationColor after attenuationDistance.
    const float distance = material.attenuation_distance;
    if (volume && distance > 0.f && std::isfinite(distance)) {
        for (int i = 0; i < 3; ++i) {
            const float color = std::clamp(saturate(material.attenuation_color[i]), kMinAttenuationColor, 1.f);
            c.absorption[i] = std::max(0.f, -std::log(color) / distance);
        }
    }

    c.emission = finite_nonneg(sample.emissive);
    return c;
}

WhittedCoeffs map_material_constant(const Material& material, const MappingOptions& options) {
    return map_gltf_material(material, constant_pbr_sample(material), options);
}

}  // namespace whitted
