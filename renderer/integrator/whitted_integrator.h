// The Whitted (1980) ray tree: local model plus recursive reflection and refraction.
#pragma once

#include <cstdint>

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
};

/// Rays traced, by kind (summed per thread, then added: integer sums are deterministic).
/// `camera` counts the primary rays whose radiance enters the image (the anti-aliasing samples);
/// `aov_probe` counts first-hit-only rays through pixel centres that feed AOVs in modes without a
/// centre sample.
struct RayCounters {
    uint64_t camera = 0, shadow = 0, reflection = 0, refraction = 0, aov_probe = 0;
    uint64_t total() const { return camera + shadow + reflection + refraction + aov_probe; }
    RayCounters& operator+=(const RayCounters& o) {
        camera += o.camera; shadow += o.shadow; reflection += o.reflection; refraction += o.refraction;
        aov_probe += o.aov_probe;
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

class WhittedIntegrator {
public:
    WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings)
        : m_view(view), m_accel(accel), m_settings(settings) {}

    /// Radiance arriving along `ray` (a unit-direction ray of the given kind at tree depth
    /// `depth`). Never NaN or infinite. `primary` (optional) receives first-hit data. `cone` is the
    /// ray's footprint for texture filtering; it is carried through reflection and refraction.
    /// `weight` is the path's accumulated kr/kt weight (1 for camera rays), compared with
    /// IntegratorSettings::min_weight before secondary rays are spawned.
    Color trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary = nullptr,
                const RayCone& cone = {}, float weight = 1.f) const;
    /// First-hit data only (no shading, no secondary rays) for a camera ray: AOVs of pixel centres
    /// in anti-aliasing modes that trace no centre sample. Counted as `aov_probe`.
    void probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const;

    const IntegratorSettings& settings() const { return m_settings; }

private:
    Color shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters, PrimaryInfo* primary,
                const RayCone& cone, float weight) const;

    const SceneView& m_view;
    const Accelerator& m_accel;
    IntegratorSettings m_settings;
};

}  // namespace whitted
