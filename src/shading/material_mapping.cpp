// glTF metallic-roughness -> Whitted (1980) coefficients. The reasons for every row are in
// docs/materials.md; the formulas are summarised in material_mapping.h.
#include "shading/material_mapping.h"
#include "shading/layer_brdfs.h"

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

void apply_specular_glossiness(const Material& material, const Vec4f& texel, PbrSample& sample) {
    sample.metallic = 0.f;
    sample.specular = 1.f;
    sample.specular_color = material.sg_specular * texel.xyz();
    sample.roughness = std::clamp(1.f - material.glossiness * texel.w, 0.f, 1.f);
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
    if (material.specular_glossiness) apply_specular_glossiness(material, Vec4f(1.f), s);
    s.clearcoat = material.clearcoat;
    s.clearcoat_roughness = material.clearcoat_roughness;
    s.sheen_color = material.sheen_color;
    s.sheen_roughness = material.sheen_roughness;
    s.iridescence = material.iridescence;
    s.iridescence_thickness = material.iridescence_thickness_max;
    s.anisotropy = material.anisotropy_strength;
    s.anisotropy_direction = {std::cos(material.anisotropy_rotation), std::sin(material.anisotropy_rotation)};
    s.diffuse_transmission = material.diffuse_transmission;
    s.diffuse_transmission_color = material.diffuse_transmission_color;
    return s;
}

AnisotropicAlpha anisotropic_alpha(float roughness, float strength) {
    const float alpha = saturate(roughness) * saturate(roughness);
    const float s = saturate(strength);
    return {alpha + (1.f - alpha) * s * s, alpha};
}

float highlight_exponent(float alpha, float max_exponent) {
    const float a = std::max(alpha, kMinAlpha);
    return std::clamp(2.f / (a * a) - 2.f, 1.f, std::max(1.f, max_exponent));
}

namespace {

/// The mapping; `layered` adds the view-dependent changes of map_layered_base at N.V = cos_v.
WhittedCoeffs map_pbr(const Material& material, const PbrSample& sample, const MappingOptions& options, bool layered,
                      float cos_v, Color* kdt) {
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
    // clamped to 1, then the specular weight), mixed towards the base color for metals. The
    // specular-glossiness model gives F0 as its specular color (the ior_to_f0 = 1 conversion).
    const float f0_ior = material.specular_glossiness ? 1.f : ior_to_f0(material.ior);
    Color f0_dielectric = vmin(finite_nonneg(sample.specular_color) * f0_ior, Color(1.f)) * saturate(sample.specular);
    Color f0_metal = base;
    if (layered && sample.iridescence > 0.f) {
        // KHR_materials_iridescence: the thin film's Fresnel at the view angle over each F0.
        const float w = saturate(sample.iridescence), d = finite_nonneg(sample.iridescence_thickness);
        const float ior = material.iridescence_ior;
        if (metallic < 1.f) f0_dielectric = lerp(f0_dielectric, iridescence_fresnel(cos_v, ior, d, f0_dielectric), w);
        if (metallic > 0.f) f0_metal = lerp(f0_metal, iridescence_fresnel(cos_v, ior, d, f0_metal), w);
    }
    const Color f0 = lerp(f0_dielectric, f0_metal, metallic);

    // Energy left under the dielectric's specular layer (glTF fresnel_mix weights its base by
    // 1 - max_value(F)), shared between the diffuse and the transmitted part.
    const float dielectric_base = (1.f - metallic) * (1.f - max_component(f0_dielectric));
    // KHR_materials_diffuse_transmission takes its share of the diffuse lobe (LayerCoeffs::kdt).
    const float diffuse_transmission = saturate(sample.diffuse_transmission);
    c.kd = base * (dielectric_base * (1.f - transmission) * (1.f - diffuse_transmission));
    if (kdt) *kdt = saturate(sample.diffuse_transmission_color) * (dielectric_base * (1.f - transmission) * diffuse_transmission);
    c.ka = c.kd * occlusion;
    c.kt = base * (dielectric_base * transmission);

    // Highlight: Phong-Blinn exponent matching a Beckmann lobe of width alpha = roughness^2
    // (Walter et al. 2007), kept finite for perfectly smooth surfaces.
    c.ks = f0;
    c.n = highlight_exponent(roughness * roughness, options.max_exponent);

    // Mirror reflection only for smooth surfaces, faded out towards the cutoff; what the mirror
    // term gives up is the glossy weight (the environment prefiltered by roughness). An
    // anisotropic surface fades by its wider direction and reads the map at the roughness of
    // the isotropic lobe of the same solid angle, sqrt(alpha_t alpha_b) (LayerCoeffs).
    float mirror_roughness = roughness, glossy_roughness = roughness;
    if (layered && sample.anisotropy > 0.f) {
        const AnisotropicAlpha a = anisotropic_alpha(roughness, sample.anisotropy);
        mirror_roughness = std::sqrt(a.t);
        glossy_roughness = std::sqrt(std::sqrt(a.t * a.b));
    }
    const float fade = mirror_fade(mirror_roughness, options.mirror_roughness_cutoff);
    c.kr = f0 * fade;
    c.kg = f0 * (1.f - fade);
    c.roughness = glossy_roughness;

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

}  // namespace

WhittedCoeffs map_gltf_material(const Material& material, const PbrSample& sample, const MappingOptions& options) {
    return map_pbr(material, sample, options, false, 1.f, nullptr);
}

WhittedCoeffs map_layered_base(const Material& material, const PbrSample& sample, const MappingOptions& options,
                               float cos_v, Color& kdt) {
    kdt = Color(0.f);
    return map_pbr(material, sample, options, true, cos_v, &kdt);
}

WhittedCoeffs map_material_constant(const Material& material, const MappingOptions& options) {
    return map_gltf_material(material, constant_pbr_sample(material), options);
}

}  // namespace whitted
