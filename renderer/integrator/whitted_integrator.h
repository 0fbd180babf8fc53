// The Whitted (1980) ray tree: local model plus recursive reflection and refraction.
//
// The shading kernel is a template on KernelFeatures: the Renderer's integrator picks one
// instantiation per render from the SceneAnalysis (opaque scenes get a kernel without the
// transmittance path, scenes without mirrors or glass one that never recurses, untextured scenes
// one without UVs or texture lookups), so the hot path carries no per-ray feature branches.
// IntegratorSettings::specialize = false forces the general kernel (--no-specialize); with
// min_weight 0 both give bit-identical images (tests/render/test_specialization.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "renderer/accel/accelerator.h"
#include "renderer/integrator/scene_view.h"

namespace whitted {

struct IntegratorSettings {
    int max_depth = 5;                 ///< maximum depth of the ray tree (camera ray = depth 0)
    Color background{0.f};             ///< radiance of rays that hit nothing
    Color ambient{0.05f};              ///< Ia, the ambient light (multiplied by Ka)
    bool fresnel = false;              ///< Schlick-weighted kr / kt instead of constant coefficients
    float min_weight = 0.f;            ///< adaptive tree depth (Hall & Greenberg 1983): a secondary ray
                                       ///< is traced only while the product of the kr/kt weights along
                                       ///< its path (max over channels) is >= this; 0 = depth limit only
                                       ///< (the CLI's default is 1/255, docs/integrator.md)
    bool specialize = true;            ///< pick the kernel the scene needs; false = the general kernel
};

/// The compile-time feature set of a shading kernel (one instantiation per combination used).
struct KernelFeatures {
    bool attributes = true;    ///< UVs, vertex colors, ray-cone footprints, per-hit material evaluation
    bool mirror = true;        ///< reflection rays (also total internal reflection)
    bool transmission = true;  ///< refraction, alpha blend, absorption, shadow transmittance products
    bool tables = false;       ///< constant materials from a table, per-object light lists
    constexpr bool operator==(const KernelFeatures&) const = default;
};

/// The kernel that handles every scene: all features, no tables (--no-specialize).
constexpr KernelFeatures kGeneralKernel{};

/// The smallest kernel that renders a scene with these features exactly like the general one.
KernelFeatures select_kernel(const SceneFeatures& scene, const IntegratorSettings& settings);

/// "general" or e.g. "specialised: opaque, no recursion, constant materials" (for logs).
std::string kernel_name(const KernelFeatures& k);

/// Rays traced, by kind (summed per thread, then added: integer sums are deterministic).
/// `camera` counts the primary rays whose radiance enters the image (the anti-aliasing samples);
/// `aov_probe` counts first-hit-only rays through pixel centres that feed AOVs in modes without a
/// centre sample. The `*_skipped` counters are not rays: shadow rays not cast because the light
/// cannot reach the point (beyond its range, outside its cone or culled per object by the scene
/// analysis: `unreached`), lies behind the surface (N.L <= 0: `facing`) or gives the point nothing
/// to shadow (kd = 0 and the highlight below the specular cutoff: `zero`), and secondary rays
/// not traced because their weight fell below min_weight (`cutoff`). `contact_probe` counts the
/// short queries for a coincident face (a touching dielectric's, or an opaque surface under a thin
/// transmissive one: in the integrator's own small structures, not the scene's accelerator; not
/// in total()).
struct RayCounters {
    uint64_t camera = 0, shadow = 0, reflection = 0, refraction = 0, aov_probe = 0;
    uint64_t shadow_skipped_unreached = 0, shadow_skipped_facing = 0, shadow_skipped_zero = 0;
    uint64_t secondary_skipped_cutoff = 0;
    uint64_t contact_probe = 0;
    uint64_t total() const { return camera + shadow + reflection + refraction + aov_probe; }
    uint64_t secondary() const { return reflection + refraction; }
    bool operator==(const RayCounters&) const = default;
    RayCounters& operator+=(const RayCounters& o) {
        camera += o.camera; shadow += o.shadow; reflection += o.reflection; refraction += o.refraction;
        aov_probe += o.aov_probe;
        shadow_skipped_unreached += o.shadow_skipped_unreached;
        shadow_skipped_facing += o.shadow_skipped_facing;
        shadow_skipped_zero += o.shadow_skipped_zero;
        secondary_skipped_cutoff += o.secondary_skipped_cutoff;
        contact_probe += o.contact_probe;
        return *this;
    }
};

/// First-hit data of a camera ray, for AOVs.
struct PrimaryInfo {
    bool hit = false;
    float depth = kInfinity;
    Vec3f normal{0.f};
    Color albedo{0.f};
    uint32_t prim = kInvalidId, inst = kInvalidId;
};

/// Where non-thin dielectrics of a scene touch (coincident faces): see whitted_integrator.cpp.
class DielectricContacts;
/// Where opaque surfaces coincide with thin transmissive ones (a transparent box standing on a
/// floor): see whitted_integrator.cpp.
class OpaqueCovers;

class WhittedIntegrator {
public:
    /// Selects the kernel for the view's scene (select_kernel) once. When two non-thin dielectrics
    /// of the scene may touch (bounds within a few ulps; spheres and planes tested exactly), also
    /// builds a small structure over those objects to find their shared faces (an in-house BVH).
    WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings);

    /// Radiance arriving along `ray` (a unit-direction ray of the given kind at tree depth
    /// `depth`). Never NaN or infinite. `primary` (optional) receives first-hit data. `cone` is the
    /// ray's footprint for texture filtering; it is carried through reflection and refraction.
    /// `weight` is the path's accumulated kr/kt weight (1 for camera rays), compared with
    /// IntegratorSettings::min_weight before secondary rays are spawned.
    Color trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary = nullptr,
                const RayCone& cone = {}, float weight = 1.f) const {
        return (this->*m_trace)(ray, kind, depth, counters, primary, cone, weight);
    }
    /// Radiance of a batch of camera rays (depth 0, path weight 1, one footprint `cone`), written to
    /// radiance[i] (radiance.size() == rays.size(), and primary.size() too when not empty; else
    /// throws). Each entry is what trace(rays[i], RayKind::Camera, 0, counters, &primary[i], cone)
    /// gives, counted the same way, except where the accelerator's batch query names another
    /// primitive at a tied closest t (Accelerator::intersect over a span). The specialised kernels
    /// issue one batch query per up to kCameraBatch rays (Embree: coherent packets) and then shade
    /// the hits one by one; the general kernel (--no-specialize) traces ray by ray, so the gain of
    /// packets stays measurable. Rows of neighbouring samples are what it is for.
    void trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                      const RayCone& cone = {}, std::span<PrimaryInfo> primary = {}) const;
    /// Rays per batch query of trace_camera (longer spans are split).
    static constexpr size_t kCameraBatch = 64;
    /// First-hit data only (no shading, no secondary rays) for a camera ray: AOVs of pixel centres
    /// in anti-aliasing modes that trace no centre sample. Counted as `aov_probe`.
    void probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const;

    const IntegratorSettings& settings() const { return m_settings; }
    /// The kernel selected for this scene and settings.
    const KernelFeatures& kernel() const { return m_kernel; }
    /// True when some non-thin dielectrics may touch, so refraction events on them look for a
    /// coincident face of the other medium (false: no query, no cost).
    bool handles_touching_dielectrics() const { return m_contacts != nullptr; }

private:
    using TraceFn = Color (WhittedIntegrator::*)(const Ray&, RayKind, int, RayCounters&, PrimaryInfo*, const RayCone&,
                                                 float) const;
    template <KernelFeatures K>
    Color trace_kernel(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary,
                       const RayCone& cone, float weight) const;
    /// Radiance along `ray` given its closest hit (the background for a miss), sanitised: what
    /// trace_kernel and trace_camera_kernel return once the accelerator has answered.
    template <KernelFeatures K>
    Color radiance_of(const Ray& ray, const Hit& hit, int depth, RayCounters& counters, PrimaryInfo* primary,
                      const RayCone& cone, float weight) const;
    using CameraFn = void (WhittedIntegrator::*)(std::span<const Ray>, std::span<Color>, RayCounters&, const RayCone&,
                                                  std::span<PrimaryInfo>) const;
    template <KernelFeatures K>
    void trace_camera_kernel(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                             const RayCone& cone, std::span<PrimaryInfo> primary) const;
    template <KernelFeatures K>
    Color shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters, PrimaryInfo* primary,
                const RayCone& cone, float weight) const;
    template <KernelFeatures K>
    static TraceFn kernel_entry() { return &WhittedIntegrator::trace_kernel<K>; }
    template <KernelFeatures K>
    static CameraFn camera_entry() { return &WhittedIntegrator::trace_camera_kernel<K>; }
    /// The medium of a touching dielectric whose face coincides with the surface hit (see
    /// DielectricContacts): its coefficients there and the point on its face.
    struct OtherMedium {
        WhittedCoeffs c;
        Vec3f p;
        float offset_scale;  ///< SurfacePoint::offset_scale of its face
    };
    /// Looks for it at a hit on a non-thin dielectric (out of line, off the kernels' hot path).
    std::optional<OtherMedium> other_medium(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const;
    /// The opaque surface coinciding with a hit on a thin transmissive object (sp: its surface
    /// point), as a hit of the same ray at the same t (OpaqueCovers), or nullopt (out of line, off
    /// the kernels' hot path).
    std::optional<Hit> opaque_cover(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const;

    const SceneView& m_view;
    const Accelerator& m_accel;
    RayOffsetPolicy m_offset;  ///< m_accel's: how far secondary-ray origins leave their surface
    IntegratorSettings m_settings;
    KernelFeatures m_kernel;
    TraceFn m_trace = nullptr;
    CameraFn m_trace_camera = nullptr;
    std::shared_ptr<const DielectricContacts> m_contacts;  ///< null when no dielectrics touch
    std::shared_ptr<const OpaqueCovers> m_covers;          ///< null when no thin transmissive object
                                                           ///< can touch an opaque one
};

}  // namespace whitted
