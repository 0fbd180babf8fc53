// The glTF layer BRDF terms: KHR_materials_sheen (the "Charlie" sheen of Conty Estevez & Kulla
// 2017) and KHR_materials_iridescence (the thin-film Fresnel of Belcour & Barla 2017).
//
// Every function is pure and thread-safe, never allocates, and returns finite values for any
// input: cosines are clamped to [0, 1] and every other argument to the documented range (NaN acts
// as the range's lower end). Schlick's Fresnel is `schlick()` in shading/optics.h.
#pragma once

#include "core/vecmath.h"

namespace whitted {

/// Smallest sheen alpha (= sheenRoughness^2) the sheen functions use: sheenRoughness below 0.1 acts
/// as 0.1, which keeps D <= 102 / (2 pi) and the albedo table smooth in roughness.
constexpr float kMinSheenAlpha = 1e-2f;
/// Smallest N.L and N.V in the sheen visibility's 1 / (4 N.L N.V): the Lambda fit does not keep it
/// bounded as a cosine goes to 0 (sheen_albedo(0, r) is the albedo at this cosine).
constexpr float kMinSheenCosine = 1e-3f;
/// Largest thin-film IOR iridescence_fresnel() uses (the schema's minimum, 1, is the smallest).
constexpr float kMaxFilmIor = 10.f;
/// Largest film thickness (nm) iridescence_fresnel() uses; the interference terms are 0 long before.
constexpr float kMaxFilmThicknessNm = 1e5f;
/// Film thicknesses (nm) over which the film fades in: the smoothstep of the Khronos code.
constexpr float kFilmFadeNm = 0.03f;

/// Charlie sheen distribution D(N.H) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi), alpha clamped
/// to [kMinSheenAlpha, 1]; its projected area, the integral of D (N.H) over the hemisphere, is 1.
float charlie_distribution(float n_dot_h, float alpha);

/// Charlie visibility G / (4 N.L N.V) with G = 1 / (1 + Lambda(N.V) + Lambda(N.L)), the spec's
/// lambda_sheen fit; alpha clamped to [kMinSheenAlpha, 1], cosines to [kMinSheenCosine, 1].
float charlie_visibility(float n_dot_l, float n_dot_v, float alpha);

/// Directional albedo E(cos_v, sheenRoughness) of the sheen BRDF D V with sheen colour 1 (the
/// integral of D V N.L over the hemisphere), clamped to [0, 1]; a bilinear table lookup.
float sheen_albedo(float cos_v, float sheen_roughness);

/// The sheen lobe seen from one direction: what D V and the albedo scaling need that does not
/// depend on the light, computed once per shading point (sheen_lobe) instead of once per light.
/// The sheen albedo table's two rows about one sheen roughness and the weight between them.
struct SheenAlbedoRows {
    const float* lo = nullptr;
    const float* hi = nullptr;
    float fy = 0.f;
};

struct SheenLobe {
    float alpha = 1.f;        ///< clamped to [kMinSheenAlpha, 1]
    float cos_v = 1.f;        ///< N.V clamped to [kMinSheenCosine, 1]
    float lambda_v = 0.f;     ///< Lambda(N.V)
    float l_half = 0.f;       ///< the Lambda fit's log at cos 0.5 (its mirror point)
    float roughness = 1.f;    ///< sheenRoughness (the albedo table's row)
    SheenAlbedoRows albedo;   ///< the table rows of `roughness`, looked up once per lobe
};
SheenLobe sheen_lobe(float n_dot_v, float sheen_roughness);

/// charlie_distribution(n_dot_h, alpha) x charlie_visibility(n_dot_l, cos_v, alpha) for the lobe,
/// and the albedo E(N.L) of the base's scaling: the per-light sheen terms.
struct SheenAtLight {
    float brdf;               ///< D V
    float albedo_l;           ///< sheen_albedo(n_dot_l, roughness)
};
SheenAtLight sheen_at_light(const SheenLobe& lobe, float n_dot_h, float n_dot_l);

/// Thin-film Fresnel of KHR_materials_iridescence at cos_theta1 = N.V (outside IOR 1), per channel
/// in [0, 1]; film_ior clamped to [1, kMaxFilmIor], thickness_nm to [0, kMaxFilmThicknessNm],
/// base_f0 to [0, 1]. Thickness 0 gives schlick(base_f0, cos_theta1).
Color iridescence_fresnel(float cos_theta1, float film_ior, float thickness_nm, const Color& base_f0);

}  // namespace whitted
