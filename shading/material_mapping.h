// glTF metallic-roughness -> the seed's Whitted coefficients (see docs/materials.md).
#pragma once

#include "renderer/scene/scene.h"

namespace whitted {

/// Settings of the mapping; every field documented in docs/materials.md.
struct MappingOptions {
    float mirror_roughness_cutoff = 0.3f;  ///< roughness at/above which mirror reflection (kr) is 0
    float max_exponent = 10000.f;          ///< clamp of the highlight exponent n
    bool refract_thin = false;             ///< --refract-thin: refract by ior even without KHR_materials_volume
};

/// The material inputs at one surface point, after texture lookups and vertex colors.
struct PbrSample {
    Vec4f base_color{1.f, 1.f, 1.f, 1.f};  ///< linear RGBA (factor * texture * vertex color)
    float metallic = 1.f;
    float roughness = 1.f;
    float transmission = 0.f;
    float occlusion = 1.f;                 ///< 1 = unoccluded (already mixed with strength)
    Color emissive{0.f};                   ///< linear, strength applied
    float specular = 1.f;                  ///< KHR_materials_specular factor * texture
    Color specular_color{1.f};
};

/// Maps the glTF inputs at a point to the seed's coefficients:
///   kd = baseColor (1 - metallic)(1 - transmission);  Ka = kd * occlusion
///   F0 = mix(dielectric F0 (from ior and KHR_materials_specular), baseColor, metallic)
///   ks = F0, n = 2/alpha^2 - 2 with alpha = roughness^2 (clamped to [1, max_exponent])
///   kr = F0 * fade(roughness) with fade 1 at roughness 0, 0 at mirror_roughness_cutoff
///   kt = transmission (1 - F0) baseColor
/// Unlit materials return kd = 0 and emission = baseColor.
WhittedCoeffs map_gltf_material(const Material& material, const PbrSample& sample, const MappingOptions& options);

/// The coefficients of a material without any texture or vertex color (for `whitted info`).
WhittedCoeffs map_material_constant(const Material& material, const MappingOptions& options);

}  // namespace whitted
