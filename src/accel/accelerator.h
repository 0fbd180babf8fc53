// Accelerator: the one interface every ray-query backend implements (docs/accelerators.md).
//
// How to use:
//   auto accel = create_accelerator("embree", scene, filter, config);   // builds once
//   Hit h = accel->intersect(ray, RayKind::Camera);                      // closest hit
//   accel->intersect(std::span(rays), RayKind::Camera, std::span(hits));  // a batch (packets)
//   Color s = accel->transmittance(shadow_ray);                          // product of Kt along it
//   auto ref = create_accelerator("bvh:precision=double", scene, filter); // double-precision reference
//
// Virtual only at the per-ray boundary; traversal inside a backend is inlined. A hit is the
// minimal record {t, u, v, prim, geom, inst}; the integrator computes shading data from it
// afterwards (Mitsuba's PreliminaryIntersection). Decisions that need materials (alpha-mask
// cut-outs, back-face culling of camera rays, transmittance) are asked of the caller's
// SurfaceFilter by geometry id, so backends never read materials or textures. Every backend
// traces Scene::spheres itself; Scene::planes are tested beside it by a decorator that
// create_accelerator adds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/ray_offset.h"
#include "core/vecmath.h"
#include "scene/scene_update.h"

namespace whitted {

struct Scene;

/// What a ray is for (statistics, and culling: only camera rays cull back faces).
enum class RayKind : uint8_t { Camera = 0, Shadow = 1, Reflection = 2, Refraction = 3 };

struct Ray {
    Vec3f org;
    Vec3f dir;                                ///< need not be unit length; t is in units of |dir|
    float tnear = 0.f;
    float tfar = kInfinity;
};

constexpr uint32_t kInvalidId = std::numeric_limits<uint32_t>::max();

/// Minimal hit record. geom is a geometry id (Scene::geom_kind): a mesh index, or for analytic
/// primitives Scene::sphere_geom_id(i) / Scene::plane_geom_id(i); inst indexes Scene::instances
/// (kInvalidId for spheres and planes, which are not instanced). For triangles prim is the
/// triangle and u, v are the barycentrics of vertices 1 and 2; for spheres and planes prim = 0
/// and u = v = 0 (shading computes their UVs from the hit point).
struct Hit {
    float t = kInfinity;
    float u = 0.f, v = 0.f;
    uint32_t prim = kInvalidId;
    uint32_t geom = kInvalidId;
    uint32_t inst = kInvalidId;
    bool valid() const { return geom != kInvalidId; }
};

/// Material-dependent decisions asked during traversal. Must be thread-safe and pure.
class SurfaceFilter {
public:
    virtual ~SurfaceFilter() = default;
    /// True when a candidate hit counts for a closest-hit query of this kind (alpha MASK
    /// cut-outs return false everywhere; camera rays also reject back faces of single-sided
    /// materials). `ray` is the caller's ray, except that its tfar may have been shortened to a
    /// nearer plane hit already accepted.
    virtual bool accept(const Ray& ray, const Hit& hit, RayKind kind) const = 0;
    /// Fraction of light a surface crossing lets through, per channel: 0 for opaque surfaces,
    /// 1 where an alpha mask cuts the surface away, Kt (or 1 - alpha for BLEND) otherwise.
    virtual Color transmittance(const Ray& ray, const Hit& hit) const = 0;
    /// What geometry `geom` (mesh, sphere or plane id) needs from traversal: a combination of the
    /// SurfaceFilter::k* flags. Backends skip the filter calls a geometry does not need (a plain
    /// opaque one needs none).
    ///
    /// The two flags are independent, one per query: kNeedsAccept is read by closest-hit queries
    /// only, kNeedsTransmittance by shadow queries only. Shadow rays never call accept(); a
    /// geometry without kNeedsTransmittance blocks a shadow ray at its first crossing, whatever
    /// accept() would say. So a geometry that lets light through anywhere (alpha-mask cut-outs,
    /// where transmittance() returns 1, as well as transparent surfaces) must set
    /// kNeedsTransmittance; single-sided opaque surfaces set kNeedsAccept alone (back faces are
    /// culled for camera rays only) and get a filter-free occlusion query.
    virtual uint32_t mesh_flags(uint32_t geom) const = 0;

    static constexpr uint32_t kNeedsAccept = 1u;         ///< closest hit: call accept() on candidates
    static constexpr uint32_t kNeedsTransmittance = 2u;  ///< shadow: call transmittance() on candidates
};

/// Counters a backend keeps (summed over threads by the caller).
struct AccelStats {
    double build_seconds = 0.0;
    size_t bytes = 0;                         ///< memory the structure holds, when known
    size_t nodes = 0;                         ///< nodes / cells / voxels (0 when not known, e.g. Embree)
    size_t references = 0;                    ///< primitive references in leaves or cells (0 = unknown)
    double sah_cost = 0.0;                    ///< SAH cost of BVH-like trees, triangle-weighted (0 = n/a)
};

/// How far a backend needs secondary-ray origins moved off their surface, and what it then
/// guarantees (src/core/ray_offset.h; docs/numerical-stability.md, section 1). The unit is
/// ulp(max(max|p|, scale_factor * SurfacePoint::offset_scale)).
struct RayOffsetPolicy {
    float ulps;          ///< the origin moves this many units along the normal (then one float step)
    float scale_factor;  ///< how much of the hit primitive's coordinate magnitude the unit follows
    float gap_ulps;      ///< every surface at least this many units in front of an origin is hit

    Vec3f origin(const Vec3f& p, float offset_scale, const Vec3f& n) const {
        return offset_ray_origin(p, scale_factor * offset_scale, n, ulps);
    }
    /// gap_ulps units as a distance: nearer surfaces may be skipped (the integrator looks for
    /// touching dielectrics within it explicitly).
    float gap(const Vec3f& p, float offset_scale) const {
        return gap_ulps * detail::offset_unit(p, scale_factor * offset_scale);
    }
};

/// Float traversal (Embree and the in-house float backends): its rounding is a few ulps of the
/// primitive's coordinates, so origins move 4 ulps of max(max|p|, the primitive's coordinates)
/// and every surface 12 of them away is hit. No offset gives both "no self-hit" and "every
/// neighbour 4 ulps away hit" with float traversal (docs/numerical-stability.md, section 1).
inline constexpr RayOffsetPolicy kFloatRayOffset{detail::kOffsetUlps, 1.f, kGuaranteedGapUlps};

/// Double traversal (bvh:precision=double, brute:precision=double): its rounding is ~2^-29 of a
/// float ulp, so the origin need only be strictly off the surface. Half an ulp of
/// max(max|p|, 2^-26 * the primitive's coordinates) (the 2^-26 floor keeps the unit above the
/// double hit point's error near the world origin) plus the float rounding puts origins 0.5 to
/// 2.5 units away, and every surface 4 ulps away is hit.
inline constexpr RayOffsetPolicy kDoubleRayOffset{0.5f, 0x1p-26f, 4.f};

class Accelerator {
public:
    virtual ~Accelerator() = default;
    /// The ray-offset policy this backend's rounding needs (kFloatRayOffset unless it traverses
    /// in double). The integrator moves every secondary-ray origin by it.
    virtual RayOffsetPolicy ray_offset() const { return kFloatRayOffset; }
    /// Closest accepted hit along [tnear, tfar], or an invalid Hit.
    virtual Hit intersect(const Ray& ray, RayKind kind) const = 0;
    /// Closest hits of a batch of rays of one kind (hits.size() == rays.size(), else throws):
    /// hits[i] is intersect(rays[i], kind), except that where several primitives meet at the
    /// closest t (shared edges and vertices) the batch may name another of them. Coherent rays
    /// (a row of camera samples) are what it is for: the Embree backend traces them as packets;
    /// the default loops over intersect().
    virtual void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const;
    /// Product of the transmittances of the distinct surfaces crossed in [tnear, tfar]; each
    /// crossing counts once (de-duplicated per (geom, inst) within a few-ulp t window). Returns
    /// exactly 0 as soon as an opaque surface is found.
    virtual Color transmittance(const Ray& ray) const = 0;
    /// Transmittances of a batch of shadow rays (out.size() == rays.size(), else throws): out[i] is
    /// transmittance(rays[i]), except that the factors of three or more transparent crossings may
    /// be multiplied in another order (a last-bit difference) and a crossing at exactly a shared
    /// edge or at tfar may be decided as by a packet. Rays toward one light from neighbouring
    /// points are what it is for: the Embree backend traces them as packets; the default loops
    /// over transmittance().
    virtual void transmittance(std::span<const Ray> rays, std::span<Color> out) const;
    /// Brings the structure up to date after the scene it was built from changed in place as
    /// `update` says (scene_update.h): deformed meshes refit, moved instances placed again, the rest
    /// untouched. Returns false when the backend cannot (the default; the caller then builds a new
    /// one). After it, every query answers as a new build over the changed scene would (the hits
    /// the same, whatever the tree's shape: exact ties follow the tie rule). Not concurrent with
    /// queries.
    virtual bool update(const SceneUpdate& update) {
        (void)update;
        return false;
    }
    /// Backend name as given to create_accelerator.
    virtual std::string name() const = 0;
    virtual AccelStats stats() const = 0;
};

/// Settings shared by all backends (each backend may add its own).
struct AccelConfig {
    bool robust = false;                      ///< Embree: RTC_SCENE_FLAG_ROBUST
    int threads = 0;                          ///< 0 = all hardware threads (build)
};

}  // namespace whitted
