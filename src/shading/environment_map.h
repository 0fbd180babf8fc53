// The environment as the renderer uses it: filtered radiance for rays that leave the scene,
// its light split into directional lights plus a spherical-harmonic ambient, and GGX prefiltered
// copies of the map and of the residual the lights leave, for rough reflections. Built once from
// an Environment; every query is const and pure, so any number of threads may share one map.
//
// Axis convention (docs/environment.md): +Y up; a map-local direction d has
//   u = 0.5 + atan2(d.z, d.x) / (2 pi),  v = acos(d.y) / pi
// so the image's centre column looks toward +X, u = 0.25 toward -Z, u = 0.75 toward +Z, and
// row 0 is the +Y pole (glTF Sample Viewer, three.js and Blender agree). The map is turned about
// +Y by rotation_deg (right-hand rule): world = R_y(rotation) * map-local.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vecmath.h"
#include "scene/environment.h"
#include "scene/scene.h"

namespace whitted {

/// Texels brighter than this times the map's mean luminance give their excess to the extracted
/// lights, whatever their number: the ambient, which nothing shadows, keeps at most 1/16 of the
/// map's light, and N lights against more differ only in how they divide the same light
/// (docs/environment.md "How the light is split").
constexpr float kExtractionThresholdFactor = 1.f / 16.f;
/// Roughness of the stored prefiltered levels; roughness 0 is the map itself.
constexpr std::array<float, 4> kPrefilterRoughness{0.25f, 0.5f, 0.75f, 1.f};

/// Real spherical-harmonic coefficients of bands 0..2 (Ramamoorthi & Hanrahan 2001 order:
/// L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22), one RGB value each.
using SH9 = std::array<Color, 9>;

/// The 9 real SH basis functions at the unit direction d.
inline std::array<float, 9> sh9_basis(const Vec3f& d) {
    return {0.282094792f,
            0.488602512f * d.y,
            0.488602512f * d.z,
            0.488602512f * d.x,
            1.092548431f * d.x * d.y,
            1.092548431f * d.y * d.z,
            0.315391565f * (3.f * d.z * d.z - 1.f),
            1.092548431f * d.x * d.z,
            0.546274215f * (d.x * d.x - d.y * d.y)};
}

/// Irradiance from radiance SH coefficients at unit normal n, divided by pi (renderer units:
/// a constant radiance L gives L), with Ramamoorthi & Hanrahan's cosine-lobe constants
/// A0 = pi, A1 = 2pi/3, A2 = pi/4; clamped at 0.
/// Inline: the ambient of every shaded point under an environment.
inline Color sh9_irradiance(const SH9& sh, const Vec3f& n) {
    // sum_i sh[i] (A_l / pi) Y_i(n), the constants folded per band: A_l / pi = 1, 2/3, 1/4.
    constexpr float c0 = 0.282094792f, c1 = 2.f / 3.f * 0.488602512f, c2 = 0.25f * 1.092548431f,
                    c20 = 0.25f * 0.315391565f, c22 = 0.25f * 0.546274215f;
    const float x = n.x, y = n.y, z = n.z;
    const Color e = sh[0] * c0 + (sh[1] * y + sh[2] * z + sh[3] * x) * c1 +
                    (sh[4] * (x * y) + sh[5] * (y * z) + sh[7] * (x * z)) * c2 + sh[6] * (c20 * (3.f * z * z - 1.f)) +
                    sh[8] * (c22 * (x * x - y * y));
    return vmax(e, Color(0.f));
}

/// The light an occluded point still receives from the scene's interreflection, from its
/// visibility alone: Jimenez et al.'s multi-bounce fit ("Practical Real-Time Strategies for
/// Accurate Indirect Occlusion", 2016, eq. 10), per channel of the receiver's albedo, which stands
/// in for its neighbours'. The ambient visibility v becomes max(v, ((a v + b) v + c) v) with
/// a = 2.0404 rho - 0.3324, b = -4.7951 rho + 0.6417, c = 2.7552 rho + 0.6903: 0 stays 0 (a closed
/// room stays dark), 1 stays exactly 1, a black receiver keeps v.
inline float multibounce_visibility(float v, float albedo) {
    if (!(v > 0.f)) return 0.f;
    if (v >= 1.f) return 1.f;
    const float rho = std::clamp(albedo, 0.f, 1.f);
    const float a = 2.0404f * rho - 0.3324f, b = -4.7951f * rho + 0.6417f, c = 2.7552f * rho + 0.6903f;
    return std::clamp(((a * v + b) * v + c) * v, v, 1.f);
}
inline Color multibounce_visibility(const Color& v, const Color& albedo) {
    return {multibounce_visibility(v.x, albedo.x), multibounce_visibility(v.y, albedo.y),
            multibounce_visibility(v.z, albedo.z)};
}

/// One light cut from the environment's brightest part (one median-cut region).
struct ExtractedLight {
    Vec3f direction{0.f, 1.f, 0.f};   ///< unit, world space, toward the light: the region's energy centroid
    Color intensity{0.f};             ///< renderer units (lux): the region's extracted power (integral of L dw) / pi
    float solid_angle = 0.f;          ///< of the region, steradians
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< the region in level-0 texels, [x0, x1) x [y0, y1)
};

/// The environment's light in two deterministic parts whose sum approximates the map's irradiance:
/// sum_k intensity_k * max(0, N.d_k) + residual_irradiance(N).
struct EnvironmentLighting {
    std::vector<ExtractedLight> lights;  ///< brightest regions, most powerful first
    SH9 residual_sh{};                ///< the ambient as radiance SH (world space): the residual's projection, plus
                                      ///< (correct_ambient) the extracted regions' projection minus their lights'
                                      ///< in bands 1-2 (band 0 of that difference is 0: each light keeps its power)
    float threshold = kInfinity;      ///< luminance above which texels were extracted (infinite: none)
    Color extracted_power{0.f};       ///< sum of the lights' integral of L dw
    Color residual_power{0.f};        ///< integral of the residual's L dw

    /// Ambient irradiance at unit normal n, renderer units (sh9_irradiance of residual_sh).
    Color residual_irradiance(const Vec3f& n) const { return sh9_irradiance(residual_sh, n); }
    /// Irradiance of lights and residual together at unit normal n, renderer units.
    Color irradiance(const Vec3f& n) const;
};

/// How EnvironmentMap::split() divides the light.
struct SplitSettings {
    int lights = kDefaultEnvironmentLights;  ///< at most this many extracted lights; 0 = everything is ambient
    float threshold_factor = kExtractionThresholdFactor;  ///< threshold T = max(factor * mean luminance, dimmest texel's)
    bool correct_ambient = true;             ///< the ambient's bands 1-2 absorb the lights' own error in those bands
};


/// A directional Light for an extracted light: travel direction -direction, colour
/// intensity / max component, intensity its max component, no attenuation.
Light to_directional_light(const ExtractedLight& light, const std::string& name);

/// Every prefiltered level (bit k = kPrefilterRoughness[k]).
inline constexpr uint32_t kAllPrefilterLevels = (1u << kPrefilterRoughness.size()) - 1u;

/// The prefiltered levels that EnvironmentMap::prefiltered() reads for any roughness in
/// [lo, hi] (clamped to [0, 1]; NaN reads as 1, as the lookup does).
uint32_t prefilter_levels_read(float lo, float hi);

class EnvironmentMap {
public:
    /// Applies 2^exposure_stops, builds the MIP pyramid and the prefiltered levels, and the same for
    /// the residual when env.extraction_threshold leaves one, on `threads` worker threads
    /// (0 = all hardware threads; the result is the same for any count).
    /// Throws whitted::Error when env.image is null or empty.
    explicit EnvironmentMap(const Environment& env, int threads = 0);
    /// What a map is built for: rendering (every lookup), or only split() (level 0 alone: no MIP
    /// pyramid, residual or prefiltered levels, so no lookup may be made).
    enum class Use { Rendering, SplitOnly };
    /// `levels`: bit k set = prefilter level k (kPrefilterRoughness[k]) is built; the others stay
    /// empty (prefilter_levels_read tells which levels a range of roughness reads; the scene
    /// analysis ORs them over the materials, so a render builds only what it looks up).
    EnvironmentMap(const Environment& env, int threads, Use use, uint32_t levels = kAllPrefilterLevels);

    /// Radiance arriving from world direction `dir` (any length; non-finite gives 0), filtered
    /// over a cone of full apex angle `cone_angle` radians: trilinear between MIP levels of the
    /// lat-long, bilinear within one (wrap in u; rows blend into the pole's mean at v = 0 and 1).
    Color radiance(const Vec3f& dir, float cone_angle = 0.f) const;

    /// radiance() of the residual: each texel scaled by min(1, T / luminance), T the extraction
    /// threshold (the extracted rest arrives as the lights). The map itself when nothing was extracted.
    Color residual_radiance(const Vec3f& dir, float cone_angle = 0.f) const;

    /// The map convolved with a GGX lobe of roughness `roughness` (alpha = roughness^2) about
    /// `dir`, normal = view = reflection direction (the split-sum prefilter); between the stored
    /// levels (kPrefilterRoughness) linear in roughness, below the first toward radiance(dir).
    Color prefiltered(const Vec3f& dir, float roughness) const;
    /// prefiltered() of the residual (below the first level toward residual_radiance(dir)).
    Color residual_prefiltered(const Vec3f& dir, float roughness) const;

    /// Splits the map's light into at most settings.lights extracted lights plus the SH ambient
    /// (0 lights: everything is ambient). Texels whose luminance exceeds the threshold T give
    /// texel * (1 - T / lum) to the lights, cut by Debevec's (2005) median cut; the rest is the
    /// residual. Deterministic; costs a summed-area table of the map (estimated_bytes).
    EnvironmentLighting split(const SplitSettings& settings) const;
    /// split() with n_lights lights and the default threshold.
    EnvironmentLighting split(int n_lights) const {
        SplitSettings settings;
        settings.lights = n_lights;
        return split(settings);
    }

    /// Irradiance at unit normal n by summing every level-0 texel, divided by pi (the reference
    /// the split is measured against; O(width * height)).
    Color brute_force_irradiance(const Vec3f& n) const;

    /// Solid-angle weighted mean radiance of the map (exposure applied).
    Color mean() const { return m_mean; }
    /// Level-0 size in texels.
    int width() const { return m_levels.front().width; }
    int height() const { return m_levels.front().height; }
    /// MIP levels, level 0 = full resolution, the last 1 x 1.
    int level_count() const { return int(m_levels.size()); }
    /// Luminance above which texels belong to the lights (Environment::extraction_threshold).
    float extraction_threshold() const { return m_threshold; }
    /// Whether the residual differs from the map (some texel exceeds the threshold) and has its own pyramid.
    bool has_residual() const { return !m_residual.empty(); }
    /// Whether camera rays that miss see the map (Environment::visible).
    bool visible() const { return m_visible; }
    /// Name of the image (Environment::image->name).
    const std::string& name() const { return m_name; }
    /// World direction from map-local and back (rotation about +Y).
    Vec3f world_from_map(const Vec3f& d) const;
    Vec3f map_from_world(const Vec3f& d) const;

    /// Bytes this map holds (MIP pyramids and prefiltered levels).
    size_t bytes() const;
    /// Upper bound on the bytes a map of width x height holds at its peak: the pyramids and
    /// prefiltered levels of the map and of its residual, and split()'s temporaries (extracted
    /// texels, summed-area table).
    static size_t estimated_bytes(int width, int height);

    /// One lat-long level: linear RGB texels, row 0 at +Y, and the mean of each pole row.
    struct Level {
        int width = 0, height = 0;
        std::vector<Color> texels;
        Color pole_top{0.f}, pole_bottom{0.f};  ///< mean of row 0 and of the last row: the value at v = 0 and v = 1
        /// Bilinear at (u, v) in [0, 1]^2: wrap in u; within half a texel of a pole, blend into the pole's mean.
        Color bilinear(float u, float v) const;
        /// bilinear's part that depends on v alone, for many lookups at one v:
        /// bilinear(u, v) = along(rows_at(v), u) for finite u and v.
        struct Rows {
            const Color* a = nullptr;  ///< the upper row, or null: the constant a_pole
            const Color* b = nullptr;  ///< the lower row, or null: the constant b_pole
            Color a_pole{0.f}, b_pole{0.f};
            float f = 0.f;             ///< the weight of b
        };
        Rows rows_at(float v) const;
        Color along(const Rows& rows, float u) const;
    };

private:
    /// The residual's pyramid: m_residual, or the map's when nothing was extracted.
    const std::vector<Level>& residual_levels() const { return m_residual.empty() ? m_levels : m_residual; }
    /// prefiltered() over one pyramid and its prefiltered levels.
    Color lookup_prefiltered(const std::vector<Level>& pyramid, const std::vector<Level>& prefiltered,
                             const Vec3f& dir, float roughness) const;

    std::vector<Level> m_levels;      ///< MIP pyramid of the lat-long (map-local)
    std::vector<Level> m_residual;    ///< MIP pyramid of the residual; empty when it equals m_levels
    std::vector<Level> m_prefiltered; ///< one per kPrefilterRoughness (map-local)
    std::vector<Level> m_residual_prefiltered;  ///< of the residual; empty when it equals the map
    Color m_mean{0.f};
    float m_threshold = kInfinity;    ///< Environment::extraction_threshold
    float m_texel_angle = 0.f;        ///< angular size of a level-0 texel, radians
    float m_cos = 1.f, m_sin = 0.f;   ///< of the rotation about +Y
    bool m_visible = true;
    std::string m_name;
};

/// Map-local direction -> (u, v) of the lat-long, both in [0, 1]; finite for every unit d.
Vec2f latlong_uv(const Vec3f& d);
/// (u, v) -> unit map-local direction.
Vec3f latlong_direction(float u, float v);

}  // namespace whitted
