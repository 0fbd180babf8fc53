// The layered glTF material extensions at one point seen from one direction (docs/materials.md,
// "Layers"): KHR_materials_clearcoat over KHR_materials_sheen over the base, whose Fresnel a
// thin film may replace (iridescence), whose highlight may be anisotropic, and whose diffuse
// lobe may let light through (diffuse transmission); dispersion splits the refracted ray.
//
//   I = (1 - w) [I_sheen + s I_base] + w I_coat,   w = clearcoat (0.04 + 0.96 (1 - Nc.V)^5)
//
// with s the sheen's albedo scaling. How to use: map_layered() gives the base's Whitted
// coefficients, already scaled by the layers above it at this view, so every term of the
// ordinary local model reads them unchanged, plus LayerCoeffs, the layers' own terms; the
// integrator adds layered_term() per light and the coat's mirror and glossy rays.
#pragma once

#include "core/vecmath.h"
#include "shading/layer_brdfs.h"
#include "shading/material_mapping.h"

namespace whitted {

/// The directions at the point: unit, world space, on the viewer's side.
struct LayerFrame {
    Vec3f V;                     ///< toward the viewer
    Vec3f N;                     ///< shading normal (normal-mapped)
    Vec3f Nc;                    ///< clearcoat normal: the clearcoat normal map, else the interpolated normal
    Vec3f T, B;                  ///< texture-space tangent and bitangent (zero: none, anisotropy is then isotropic)
};

/// What the layers add at one point seen from V (map_layered).
struct LayerCoeffs {
    // KHR_materials_clearcoat
    float coat = 0.f;            ///< w: clearcoat x the coat's Schlick Fresnel at Nc.V (F0 = 0.04)
    float coat_n = 1.f;          ///< the coat's highlight exponent (clearcoat roughness)
    float coat_kr = 0.f;         ///< the coat's mirror weight, w x fade(clearcoat roughness)
    float coat_kg = 0.f;         ///< the coat's glossy weight, w x (1 - fade)
    float coat_roughness = 0.f;  ///< clearcoat roughness
    Vec3f Nc;                    ///< the coat's normal (viewer's side)
    // KHR_materials_sheen
    Color sheen{0.f};            ///< (1 - w) sheenColor: the Charlie lobe's weight; 0 = no sheen
    SheenLobe sheen_lobe;        ///< the Charlie lobe's view-dependent parts (sheenRoughness, N.V)
    float sheen_max = 0.f;       ///< max(sheenColor): the base under it keeps 1 - sheen_max E(cos)
    float base_v = 1.f;          ///< 1 - sheen_max E(N.V): the scaling already in the base's coefficients
    Color sheen_ambient{0.f};    ///< (1 - w) sheenColor E(N.V): the lobe's albedo (multiplies Ia)
    float cos_v = 1.f;           ///< N.V
    // KHR_materials_anisotropy
    bool anisotropic = false;
    float n_t = 1.f, n_b = 1.f;  ///< highlight exponents along T and B (Ashikhmin & Shirley 2000)
    Vec3f T, B;                  ///< the anisotropy direction and its perpendicular, in the tangent plane
    Vec3f glossy_normal;         ///< normal the glossy term reflects V about (bent toward the anisotropy)
    // KHR_materials_diffuse_transmission
    Color kdt{0.f};              ///< diffuse weight of light arriving from behind (layers above included)
    // KHR_materials_dispersion
    float dispersion = 0.f;      ///< 20 / Abbe number; > 0 and not thin: one refracted ray per channel
    // The environment's extracted lights
    float environment_scale = 1.f;       ///< environment_highlight_scale of the base's exponent
    float coat_environment_scale = 1.f;  ///< and of the coat's
};

/// The base's coefficients at the point seen from f.V, scaled by the layers above it, and the
/// layers' own terms in `layers`:
///   base (map_layered_base at N.V) times (1 - w) base_v, its emission times (1 - w) only;
///   w, coat_n, coat_kr, coat_kg as LayerCoeffs says; sheen = (1 - w) sheenColor;
///   kdt = diffuseTransmissionColor x the diffuse lobe's weight x diffuseTransmission x (1 - w) base_v.
WhittedCoeffs map_layered(const Material& material, const PbrSample& sample, const LayerFrame& f,
                          const MappingOptions& options, LayerCoeffs& layers);

/// The layered local term of one light from unit direction L, n_dot_l = N.L, before the light's
/// intensity and shadow factor (pi f N.L in Whitted's light units):
///   N.L > 0: base (kd N.L + highlight) min(1, (1 - sheen_max E(N.L)) / base_v)
///            + pi sheen D(N.H) V(N.L, N.V) N.L + w (Nc.H)^coat_n   (coat only where Nc.L > 0)
///   N.L < 0: kdt |N.L|
/// The highlight is (N.H)^n, or with anisotropy (N.H)^((n_t (T.H)^2 + n_b (B.H)^2) / (1 - (N.H)^2)).
/// environment_light: the light was extracted from an environment (highlights scaled by
/// environment_highlight_scale of their exponent).
Color layered_term(const WhittedCoeffs& c, const LayerCoeffs& l, const Vec3f& N, const Vec3f& L, const Vec3f& V,
                   float n_dot_l, bool environment_light);

/// KHR_materials_dispersion's indices of refraction for red, green and blue:
/// ior - h, ior, ior + h with h = (ior - 1) 0.025 dispersion.
Color dispersion_iors(float ior, float dispersion);

}  // namespace whitted
