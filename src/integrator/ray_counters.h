// What one render traced and skipped, by kind, and the first-hit data that feeds the AOVs.
#pragma once

#include <cstdint>

#include "accel/accelerator.h"

namespace whitted {

/// Rays traced, by kind (summed per thread, then added: integer sums are deterministic).
/// The `*_skipped` counters are not rays: they count the rays the integrator proved unnecessary.
struct RayCounters {
    uint64_t camera = 0;      ///< primary rays whose radiance enters the image (anti-aliasing samples)
    uint64_t shadow = 0;
    uint64_t reflection = 0;
    uint64_t refraction = 0;  ///< refracted, straight-through (thin) and alpha-blend rays
    uint64_t aov_probe = 0;   ///< first-hit-only rays through pixel centres, for AOVs in modes without a centre sample
    uint64_t occlusion = 0;   ///< rays that test whether the environment's ambient reaches a point
    uint64_t shadow_skipped_unreached = 0;  ///< light beyond its range, outside its cone, or culled per object
    uint64_t shadow_skipped_facing = 0;     ///< light behind the surface (N.L <= 0)
    uint64_t shadow_skipped_zero = 0;       ///< nothing to shadow: kd = 0 and the highlight below the cutoff
    uint64_t shadow_skipped_dim = 0;        ///< an environment light's term below min_weight at the point
    uint64_t occlusion_skipped_dim = 0;     ///< occlusion directions left untested below min_weight
    uint64_t secondary_skipped_cutoff = 0;  ///< secondary rays whose path weight fell below min_weight
    uint64_t contact_probe = 0;             ///< short queries for a coincident face (contacts.h); not in total()
    uint64_t total() const { return camera + shadow + reflection + refraction + aov_probe + occlusion; }
    uint64_t secondary() const { return reflection + refraction; }
    bool operator==(const RayCounters&) const = default;
    RayCounters& operator+=(const RayCounters& o) {
        camera += o.camera; shadow += o.shadow; reflection += o.reflection; refraction += o.refraction;
        aov_probe += o.aov_probe;
        occlusion += o.occlusion;
        occlusion_skipped_dim += o.occlusion_skipped_dim;
        shadow_skipped_unreached += o.shadow_skipped_unreached;
        shadow_skipped_facing += o.shadow_skipped_facing;
        shadow_skipped_zero += o.shadow_skipped_zero;
        shadow_skipped_dim += o.shadow_skipped_dim;
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

}  // namespace whitted
