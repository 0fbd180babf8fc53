// The Whitted (1980) ray tree: at the nearest hit the local model plus recursive reflection and
// refraction, to a maximum depth (docs/integrator.md).
//
//   I = emission + Ia ka + sum_i Is_i fat_i s_i (kd N.L_i + ks (N.H_i)^n) + kt T + kr R + kg G
//
// kg G, the glossy reflection of an environment (no ray: the prefiltered map), is the extension
// for surfaces too rough for the mirror term (docs/environment.md).
//
// The shading code is a template on KernelFeatures (kernel_features.h): each render runs the
// smallest instantiation its scene needs, so the hot path carries no per-ray feature branches.
#pragma once

#include <algorithm>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "accel/accelerator.h"
#include "core/ray_offset.h"
#include "integrator/kernel_features.h"
#include "integrator/ray_counters.h"
#include "integrator/scene_view.h"
#include "integrator/shading_frame.h"
#include "shading/light_sample.h"
#include "shading/sample_sets.h"

namespace whitted {

/// Default of --env-occlusion: directions per shading point over which the environment's ambient
/// is occluded (docs/environment.md, "Occlusion"); the glossy rays are a quarter of it.
constexpr int kDefaultEnvOcclusion = 25;
/// Levels of sub-cells an occlusion cell on an occluder's edge is refined into (2: 16 sub-cells).
constexpr int kOcclusionLevels = 2;
/// Glossy reflection rougher than this takes the prefiltered map times the ambient's visibility
/// instead of rays over its lobe.
constexpr float kGlossyRayRoughness = 0.6f;
/// Glossy rays over a lobe for an --env-occlusion budget (a quarter, at least 1; 0 for 0).
constexpr int kMaxGlossyRays = 64;
constexpr int glossy_ray_count(int budget) { return budget <= 0 ? 0 : std::clamp(budget / 4, 1, kMaxGlossyRays); }
/// Largest --env-occlusion budget.
constexpr int kMaxEnvOcclusion = 1024;

struct IntegratorSettings {
    int max_depth = 5;                 ///< maximum depth of the ray tree (camera ray = depth 0)
    Color background{0.f};             ///< radiance of rays that hit nothing
    Color ambient{0.05f};              ///< Ia, the ambient light (multiplied by Ka)
    bool fresnel = false;              ///< Schlick-weighted kr / kt instead of constant coefficients
    float min_weight = 0.f;            ///< adaptive tree depth (Hall & Greenberg 1983): a secondary ray
                                       ///< is traced only while the product of the kr/kt weights along
                                       ///< its path (max over channels) is >= this; 0 = depth limit only
    bool specialize = true;            ///< pick the kernel the scene needs; false = the general kernel
    bool environment_ambient = true;   ///< with an environment, Ia is its ambient light (SH irradiance at N);
                                       ///< false (an `ambient` given): the constant `ambient`
    bool environment_visible = true;   ///< camera rays that miss see the environment; false (a `background`
                                       ///< given, or the environment's `visible` false): the background
    int env_occlusion = kDefaultEnvOcclusion;  ///< with an environment: directions per point that occlude its
                                       ///< ambient, and 4 times the glossy rays over a rough lobe; 0 = off
                                       ///< (the ambient unshadowed, the glossy term the prefiltered map alone)
};

class DielectricContacts;
class OpaqueCovers;

class WhittedIntegrator {
public:
    /// Selects the kernel for the view's scene once, and builds the contact structures
    /// (contacts.h) when the scene has objects whose faces may coincide.
    WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings);

    /// Radiance arriving along `ray` (unit direction, of the given kind, at tree depth `depth`);
    /// never NaN or infinite. `primary` (optional) receives first-hit data. `cone` is the ray's
    /// footprint for texture filtering, carried through reflection and refraction. `weight` is the
    /// path's accumulated kr/kt weight (1 for camera rays), compared with min_weight.
    Color trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary = nullptr,
                const RayCone& cone = {}, float weight = 1.f) const {
        return (this->*m_trace)(ray, kind, depth, counters, primary, cone, weight);
    }
    /// Radiance of a batch of camera rays (depth 0, weight 1, one footprint): radiance[i] is what
    /// trace(rays[i], RayKind::Camera, 0, counters, &primary[i], cone) gives, except where the batch
    /// query names another primitive at a tied closest t. The specialised kernels issue one batch
    /// query (Embree: coherent packets) per kCameraBatch rays; the general kernel traces one by one.
    /// Throws when the spans' sizes differ (`primary` may be empty).
    void trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                      const RayCone& cone = {}, std::span<PrimaryInfo> primary = {}) const;
    /// Rays per batch query of trace_camera (longer spans are split).
    static constexpr size_t kCameraBatch = 64;
    /// First-hit data only (no shading, no secondary rays) for a camera ray, counted as `aov_probe`.
    void probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const;

    const IntegratorSettings& settings() const { return m_settings; }
    /// The kernel selected for this scene and settings.
    const KernelFeatures& kernel() const { return m_kernel; }
    /// True when some non-thin dielectrics may touch (refraction looks for the other medium's face).
    bool handles_touching_dielectrics() const { return m_contacts != nullptr; }

private:
    /// The medium of a touching dielectric whose face coincides with the surface hit.
    struct OtherMedium {
        WhittedCoeffs c;
        Vec3f p;             ///< the point on its face
        float offset_scale;  ///< SurfacePoint::offset_scale of its face
    };
    /// One hit being shaded: what every term of the formula reads.
    struct Shading {
        const Ray& ray;
        const Hit& hit;
        const SurfacePoint& sp;
        const WhittedCoeffs& c;
        const Material& mat;
        const MaterialFeatures& mf;              ///< what the scene analysis knows of mat
        const ShadingFrame& f;                   ///< shade()'s frame (held, not copied: the copy stalled)
        const std::optional<OtherMedium> other;  ///< a touching dielectric's medium beyond the surface
        const int depth;
        const RayCone secondary;                 ///< footprint the secondary rays start with
        const float weight;                      ///< path weight of the ray that hit
        const LayerCoeffs* layers;               ///< a layered material's layers (c is their base); null otherwise
    };

    template <KernelFeatures K>
    Color trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary,
                const RayCone& cone, float weight) const;
    template <KernelFeatures K>
    void trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                      const RayCone& cone, std::span<PrimaryInfo> primary) const;
    /// Radiance along `ray` given its closest hit (the background for a miss), never NaN or inf.
    template <KernelFeatures K>
    Color shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters, PrimaryInfo* primary,
                const RayCone& cone, float weight) const;

    // The terms of the formula, each at one hit (whitted_integrator.cpp).
    /// What a ray that leaves the scene sees: the environment (filtered by the ray's cone), or the
    /// background (no environment, or a camera ray when the environment is not visible).
    Color missed(const Ray& ray, int depth, const RayCone& cone) const;
    /// Ia at the hit: the environment's ambient light in the direction of N, or the constant.
    Color ambient_light(const Vec3f& N) const;
    /// The layers' ambient terms: the sheen lobe's albedo (returned) and diffuse transmission from
    /// behind (`behind`).
    Color layered_ambient(const Shading& s, Color& behind) const;
    /// The share of the environment's ambient that reaches the point past the scene, per channel
    /// (1 = nothing in the way): a grid of m_occlusion about N, each cell weighted by the ambient's
    /// radiance from it and tested adaptively (Ward 1991), the cells on an occluder's edge refined.
    /// `stake`: the most the terms it scales can give at this point and material (any normal), which
    /// sets the grid's size and bounds the error of what is not traced.
    Color environment_visibility(const Shading& s, float stake, RayCounters& counters) const;
    template <KernelFeatures K>
    Color direct_light(Color sum, const Shading& s, RayCounters& counters) const;
    template <KernelFeatures K>
    Color transmitted(const Shading& s, const Color& kt, Color& kr, RayCounters& counters) const;
    /// kr R about the shading normal N (the coat's normal for a clearcoat's own ray).
    template <KernelFeatures K>
    Color reflected(const Shading& s, const Color& kr, const Vec3f& N, RayCounters& counters) const;
    /// The coat's mirror ray (one ray with the base's when their normals agree) and glossy term.
    template <KernelFeatures K>
    Color coat_reflection(const Shading& s, Color& kr, RayCounters& counters) const;
    /// kg G: the environment prefiltered by `roughness` about V mirrored on N (0 without an
    /// environment). n: the lobe's highlight exponent. With occlusion on, rays over the lobe
    /// below kGlossyRayRoughness (glossy_rays), above it the map times `visible`.
    template <KernelFeatures K>
    Color glossy(const Shading& s, const Color& kg, const Vec3f& N, float roughness, float n, const Color& visible,
                 RayCounters& counters) const;
    /// G seen through the scene: GGX half vectors about N (a fixed Hammersley set), each reflected
    /// ray traced, what it hits shaded by seen_in_lobe, `G` (the prefiltered map) where it leaves.
    template <KernelFeatures K>
    Color glossy_rays(const Shading& s, const Color& kg, const Vec3f& N, float roughness, const Color& G,
                      RayCounters& counters) const;
    /// What a glossy ray that hit sees there, shaded smoothly (no shadow, highlight or recursion).
    Color seen_in_lobe(const Ray& ray, const Hit& hit, const RayCone& cone, float roughness) const;
    /// kt T split per channel through a dispersive surface (KHR_materials_dispersion).
    template <KernelFeatures K>
    Color dispersed(const Shading& s, const Ray& t, const Color& kt, const Color& kt_through, float other_eta, float w,
                    Color& kr, RayCounters& counters) const;
    Color absorbed(const Shading& s, Color radiance) const;
    /// The shadow ray from `org` toward the light (s_i is the accelerator's transmittance along
    /// it), written into `shadow`; false (none) when the point is at the light itself.
    static bool shadow_ray(const Light& light, const LightSample& ls, const Vec3f& org, Ray& shadow);
    /// True when a secondary ray of path weight w is worth tracing (w >= min_weight); counts the cut.
    bool worth_tracing(float w, RayCounters& counters) const;
    template <KernelFeatures K>
    Color blend_behind(const Shading& s, const Color& radiance, RayCounters& counters) const;

    // What the kernels need at a hit, per kernel.
    const MaterialFeatures& features(const Hit& hit) const {
        return m_view.analysis().materials[m_view.scene().geom_material(hit.geom)];
    }
    template <KernelFeatures K>
    SurfacePoint surface_point(const Ray& ray, const Hit& hit, const MaterialFeatures& mf, const RayCone& cone) const;
    template <KernelFeatures K>
    const WhittedCoeffs& coefficients(const MaterialFeatures& mf, const SurfacePoint& sp, WhittedCoeffs& varying) const;
    template <KernelFeatures K>
    std::optional<OtherMedium> touching_medium(const Hit& hit, const SurfacePoint& sp, const WhittedCoeffs& c,
                                               RayCounters& counters) const;
    /// The opaque surface lying under a hit on a thin transmissive object, as this ray's hit.
    std::optional<Hit> covering_surface(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const;
    // Out of line, off the kernels' hot path.
    std::optional<OtherMedium> other_medium(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const;
    std::optional<Hit> opaque_cover(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const;

    using TraceFn = Color (WhittedIntegrator::*)(const Ray&, RayKind, int, RayCounters&, PrimaryInfo*, const RayCone&,
                                                 float) const;
    using CameraFn = void (WhittedIntegrator::*)(std::span<const Ray>, std::span<Color>, RayCounters&, const RayCone&,
                                                  std::span<PrimaryInfo>) const;

    const SceneView& m_view;
    const Accelerator& m_accel;
    RayOffsetPolicy m_offset;  ///< m_accel's: how far secondary-ray origins leave their surface
    IntegratorSettings m_settings;
    KernelFeatures m_kernel;
    const EnvironmentMap* m_environment = nullptr;             ///< null: misses see the background
    const std::array<Color, 9>* m_ambient_sh = nullptr;        ///< null: the constant ambient
    std::vector<HemisphereGrid> m_occlusion;  ///< n x n cells of the cosine-weighted hemisphere for n = 1, 2, ..;
                                          ///< empty: the ambient is not occluded
    float m_ambient_max = 0.f;            ///< largest channel of the ambient's irradiance over all normals
    int m_glossy_rays = 0;                ///< rays over a glossy lobe of weight 1; 0: the prefiltered map alone
    std::array<Color, 9> m_lights_sh{};   ///< the extracted lights as radiance SH9 (seen_in_lobe)
    TraceFn m_trace = nullptr;          ///< trace<m_kernel>
    CameraFn m_trace_camera = nullptr;  ///< trace_camera<m_kernel>
    std::shared_ptr<const DielectricContacts> m_contacts;  ///< null when no dielectrics touch
    std::shared_ptr<const OpaqueCovers> m_covers;          ///< null when no transmissive object
                                                           ///< can touch an opaque one
};

}  // namespace whitted
