// glTF metallic-roughness -> Whitted's (1980) coefficients (see docs/materials.md).
//
// How to use: at a hit point the caller looks up the material's textures (shading/texture_sampling)
// and fills a PbrSample following the field contracts below, then calls map_gltf_material(). The
// mapping itself never reads textures, never allocates and is pure (safe from any thread).
// Alpha (MASK cut-outs, BLEND coverage) is not part of the mapping: the integrator reads
// Material::alpha_mode / alpha_cutoff and PbrSample::base_color.w itself.
#pragma once

#include "scene/scene.h"

namespace whitted {

/// Clamp to [0, 1] with NaN -> 0 (per channel for colours): how the mappings read their inputs.
inline float saturate(float x) { return x > 0.f ? (x < 1.f ? x : 1.f) : 0.f; }
inline Color saturate(const Color& c) { return {saturate(c.x), saturate(c.y), saturate(c.z)}; }

/// Settings of the mapping; every field documented in docs/materials.md.
struct MappingOptions {
    float mirror_roughness_cutoff = 0.3f;  ///< roughness at/above which mirror reflection (kr) is 0; <= 0 disables kr
    float max_exponent = 10000.f;          ///< clamp of the highlight exponent n (values < 1 act as 1)
    bool refract_thin = false;             ///< --refract-thin: refract by ior even without KHR_materials_volume
};

/// The material inputs at one surface point, after texture lookups and vertex colors.
/// Every product listed is formed by the caller; the mapping uses the values as final.
/// Out-of-range values are clamped by the mapping (factors and base color to [0,1], specular color
/// and emission to finite values >= 0; NaN -> 0).
struct PbrSample {
    Vec4f base_color{1.f, 1.f, 1.f, 1.f};  ///< linear RGBA: baseColorFactor * baseColorTexture * COLOR_0
    float metallic = 1.f;                  ///< metallicFactor * metallicRoughnessTexture.b
    float roughness = 1.f;                 ///< roughnessFactor * metallicRoughnessTexture.g (perceptual)
    float transmission = 0.f;              ///< transmissionFactor * transmissionTexture.r
    float occlusion = 1.f;                 ///< 1 + strength * (occlusionTexture.r - 1); 1 = unoccluded
    Color emissive{0.f};                   ///< final linear emission: emissiveFactor * emissiveTexture.rgb * emissive_strength
    float specular = 1.f;                  ///< KHR_materials_specular specularFactor * specularTexture.a
    Color specular_color{1.f};             ///< specularColorFactor * specularColorTexture.rgb (linear, may exceed 1);
                                           ///< specular-glossiness: specularFactor * texture.rgb, used as F0
    // The layered extensions (0 = off), factor x texture channel (docs/materials.md, "Layers").
    float clearcoat = 0.f;                 ///< clearcoatFactor * clearcoatTexture.r
    float clearcoat_roughness = 0.f;       ///< clearcoatRoughnessFactor * clearcoatRoughnessTexture.g
    Color sheen_color{0.f};                ///< sheenColorFactor * sheenColorTexture.rgb
    float sheen_roughness = 0.f;           ///< sheenRoughnessFactor * sheenRoughnessTexture.a
    float iridescence = 0.f;               ///< iridescenceFactor * iridescenceTexture.r
    float iridescence_thickness = 0.f;     ///< nm: mix(minimum, maximum, thicknessTexture.g), maximum without a texture
    float anisotropy = 0.f;                ///< anisotropyStrength * anisotropyTexture.b
    Vec2f anisotropy_direction{1.f, 0.f};  ///< unit direction in (tangent, bitangent), rotation applied
    float diffuse_transmission = 0.f;      ///< diffuseTransmissionFactor * texture.a
    Color diffuse_transmission_color{1.f}; ///< diffuseTransmissionColorFactor * texture.rgb
};


/// Maps the glTF inputs at a point to Whitted's coefficients (m = metallic, t = transmission,
/// r = roughness; F0d = dielectric F0 per KHR_materials_specular; max() = largest channel):
///   F0 = mix(F0d, baseColor, m),  F0d = min(ior_to_f0(ior) * specularColor, 1) * specular
///   kd = baseColor (1 - m)(1 - t)(1 - max F0d);  ka = kd * occlusion
///   ks = F0, n = 2/alpha^2 - 2 with alpha = max(r^2, 1e-3), clamped to [1, max_exponent]
///   kr = F0 * fade(r), fade = 1 - smoothstep(0, mirror_roughness_cutoff, r)
///   kg = F0 * (1 - fade(r)), roughness = r (the glossy reflection of the environment)
///   kt = baseColor (1 - m) t (1 - max F0d)      (= t (1 - F0) baseColor for a dielectric)
///   thin unless KHR_materials_volume (or options.refract_thin for transmissive materials);
///   absorption = -ln(attenuationColor) / attenuationDistance inside a volume
///   emission = sample.emissive
/// Per channel ks + kt <= 1, kr + kg = ks and kd + kr + kg + kt <= 1. Unlit materials return emission = baseColor
/// and every other coefficient 0; MaterialModel::Classic returns material.classic unchanged.
WhittedCoeffs map_gltf_material(const Material& material, const PbrSample& sample, const MappingOptions& options);

/// The base layer of a layered material seen at N.V = cos_v: map_gltf_material plus what the
/// layered extensions change in it. KHR_materials_iridescence: F0 (dielectric and metal) becomes
/// mix(F0, iridescence_fresnel(cos_v, iridescence_ior, thickness, F0), iridescence).
/// KHR_materials_anisotropy: the mirror fade uses the wider roughness sqrt(alpha_t), the glossy
/// term the roughness sqrt(sqrt(alpha_t alpha_b)). KHR_materials_diffuse_transmission (in both
/// mappings): kd keeps (1 - dt) of the diffuse lobe, and `kdt` receives the transmitted share,
/// diffuseTransmissionColor (1 - m)(1 - t)(1 - max F0d) dt.
WhittedCoeffs map_layered_base(const Material& material, const PbrSample& sample, const MappingOptions& options,
                               float cos_v, Color& kdt);

/// Anisotropic GGX widths of KHR_materials_anisotropy: alpha_t = mix(alpha, 1, strength^2) along the
/// anisotropy direction, alpha_b = alpha across it, alpha = roughness^2.
struct AnisotropicAlpha {
    float t, b;
};
AnisotropicAlpha anisotropic_alpha(float roughness, float strength);

/// The highlight exponent n = 2/alpha^2 - 2 of a GGX/Beckmann width alpha (floored at 1e-3),
/// clamped to [1, max_exponent] (Walter et al. 2007).
float highlight_exponent(float alpha, float max_exponent);

/// The coefficients of a material without any texture or vertex color (for `whitted info`).
WhittedCoeffs map_material_constant(const Material& material, const MappingOptions& options);

/// KHR_materials_pbrSpecularGlossiness at a point: metallic 0, F0 = specularFactor x texel.rgb (as
/// specular_color with specular 1), roughness = 1 - glossinessFactor x texel.a; the diffuse colour
/// is the base colour, already read. `texel`: the specularGlossinessTexture's (1 without one).
void apply_specular_glossiness(const Material& material, const Vec4f& texel, PbrSample& sample);

/// The PbrSample built from a material's factors alone (textures and vertex colors ignored).
PbrSample constant_pbr_sample(const Material& material);

/// Normal-incidence Fresnel reflectance of a dielectric against air: ((ior - 1)/(ior + 1))^2.
/// 0.04 at ior 1.5, 0 at ior 1; ior 0 or infinity give 1 (KHR_materials_specular conversions).
float ior_to_f0(float ior);

/// Weight of the mirror term: 1 at roughness 0, 1 - smoothstep(0, cutoff, roughness) above,
/// 0 at and above the cutoff (and everywhere when cutoff <= 0).
float mirror_fade(float roughness, float cutoff);

}  // namespace whitted
