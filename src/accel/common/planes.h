// Infinite planes (Scene::planes) beside any backend. A plane has no finite bounds, so it is kept
// out of every acceleration structure: create_accelerator wraps the backend in a PlaneDecorator
// when the scene has planes, and every backend (Embree included) supports them the same way.
//   - closest hit: the nearest accepted plane hit shortens the ray, then the backend is asked for
//     a hit up to it (a backend hit at exactly the same t wins);
//   - transmittance: the planes' crossings (each plane is crossed at most once), then the
//     backend's transmittance; exactly 0 as soon as an opaque surface is found.
// Filter semantics are those of meshes (queries.h): accept() only with kNeedsAccept, for closest
// hits; a shadow ray stops at a plane without kNeedsTransmittance.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "accel/accelerator.h"
#include "accel/common/geometry.h"
#include "core/error.h"
#include "scene/scene.h"

namespace whitted {

/// Intersects the ray with the plane dot(normal, p - point) = 0, from either side. The distance
/// is computed in double and rounded to float; a hit needs tnear < t <= tfar (in float, so a ray
/// whose tfar is a reported hit finds it again) and a finite t. Rays parallel to the plane
/// (dot(normal, dir) == +0 or -0), including rays lying in it, never hit.
inline bool intersect_plane(const Ray& ray, const Vec3d& point, const Vec3d& normal, float& t_out) {
    const double denom = dot(normal, Vec3d(ray.dir));
    if (denom == 0.0 || std::isnan(denom)) return false;
    const float t = float(dot(normal, point - Vec3d(ray.org)) / denom);
    if (!(t > ray.tnear && t <= ray.tfar) || std::isinf(t)) return false;
    t_out = t;
    return true;
}

/// Adds a scene's infinite planes to a backend that knows only finite geometry.
class PlaneDecorator final : public Accelerator {
public:
    using Accelerator::intersect;
    using Accelerator::transmittance;
    /// Takes ownership of `inner`, which was built for the same scene and filter.
    PlaneDecorator(std::unique_ptr<Accelerator> inner, const Scene& scene, const SurfaceFilter& filter)
        : m_inner(std::move(inner)), m_filter(filter) {
        for (size_t i = 0; i < scene.planes.size(); ++i) {
            const Plane& p = scene.planes[i];
            if (!is_finite(p.point) || !is_finite(p.normal) || dot(p.normal, p.normal) == 0.0) continue;
            const uint32_t geom = scene.plane_geom_id(i);
            m_planes.push_back({p.point, p.normal, geom, filter.mesh_flags(geom)});
        }
    }

    Hit intersect(const Ray& ray, RayKind kind) const override {
        // One named result, returned in place: the backend writes its hit straight into it (a copy
        // of that hit, just written by the backend's narrower stores, stalled). An untraceable ray
        // stays so (clipped = ray), and the backend misses it too.
        const bool traceable = ray_is_traceable(ray);
        Ray clipped = ray;
        const Hit best = traceable ? nearest_plane(ray, kind, clipped) : Hit{};
        Hit h = m_inner->intersect(clipped, kind);
        if (!h.valid()) h = best;
        return h;
    }

    /// As intersect() per ray, with the backend's batch query on the clipped rays (in chunks, so
    /// the scratch lives on the stack).
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        RT_CHECK_EQ(rays.size(), hits.size());
        constexpr size_t kChunk = 64;  // a multiple of every packet width
        Ray clipped[kChunk];
        Hit planes[kChunk];
        for (size_t base = 0; base < rays.size(); base += kChunk) {
            const size_t n = std::min(kChunk, rays.size() - base);
            for (size_t i = 0; i < n; ++i) {
                // Untraceable rays stay so (clipped = ray): the backend's batch misses them too.
                clipped[i] = rays[base + i];
                planes[i] = ray_is_traceable(rays[base + i]) ? nearest_plane(rays[base + i], kind, clipped[i]) : Hit{};
            }
            m_inner->intersect(std::span<const Ray>(clipped, n), kind, hits.subspan(base, n));
            for (size_t i = 0; i < n; ++i)
                if (!hits[base + i].valid()) hits[base + i] = planes[i];
        }
    }

    /// Planes do not move (scene_update.h): the backend's update.
    bool update(const SceneUpdate& update) override { return m_inner->update(update); }

    Color transmittance(const Ray& ray) const override {
        if (!ray_is_traceable(ray)) return Color(1.f);
        Color tr = plane_transmittance(ray);
        if (is_black(tr)) return Color(0.f);
        tr *= m_inner->transmittance(ray);
        return is_black(tr) ? Color(0.f) : tr;
    }

    /// As transmittance() per ray, with the backend's batch query for what lies beyond the planes.
    void transmittance(std::span<const Ray> rays, std::span<Color> out) const override {
        RT_CHECK_EQ(rays.size(), out.size());
        constexpr size_t kChunk = 64;
        Color planes[kChunk];
        for (size_t base = 0; base < rays.size(); base += kChunk) {
            const size_t n = std::min(kChunk, rays.size() - base);
            for (size_t i = 0; i < n; ++i) planes[i] = plane_transmittance(rays[base + i]);
            m_inner->transmittance(rays.subspan(base, n), out.subspan(base, n));
            for (size_t i = 0; i < n; ++i) {
                const Color tr = is_black(planes[i]) ? Color(0.f) : planes[i] * out[base + i];
                out[base + i] = is_black(tr) ? Color(0.f) : tr;
            }
        }
    }

    std::string name() const override { return m_inner->name(); }
    /// The planes are exact to a float rounding of t (intersect_plane): the backend's policy.
    RayOffsetPolicy ray_offset() const override { return m_inner->ray_offset(); }
    AccelStats stats() const override {
        AccelStats s = m_inner->stats();
        s.bytes += m_planes.size() * sizeof(PlaneData);
        return s;
    }

private:
    /// The nearest accepted plane hit of a traceable ray (lowest index on equal t), and in
    /// `clipped` the ray the backend is then asked: up to that hit, so that geometry in front of
    /// (or exactly at) the plane hides it.
    Hit nearest_plane(const Ray& ray, RayKind kind, Ray& clipped) const {
        Hit best;
        clipped = ray;
        for (const PlaneData& p : m_planes) {
            float t;
            if (!intersect_plane(clipped, p.point, p.normal, t) || (best.valid() && t >= best.t)) continue;
            const Hit h = plane_hit(p, t);
            if ((p.flags & SurfaceFilter::kNeedsAccept) && !m_filter.accept(ray, h, kind)) continue;
            best = h;
        }
        if (best.valid()) clipped.tfar = best.t;
        return best;
    }

    /// The product of the planes' transmittances along a shadow ray (exactly 0 once one blocks
    /// it); 1 for an untraceable ray.
    Color plane_transmittance(const Ray& ray) const {
        Color tr(1.f);
        if (!ray_is_traceable(ray)) return tr;
        for (const PlaneData& p : m_planes) {
            float t;
            if (!intersect_plane(ray, p.point, p.normal, t)) continue;
            if (!(p.flags & SurfaceFilter::kNeedsTransmittance)) return Color(0.f);
            tr *= m_filter.transmittance(ray, plane_hit(p, t));
            if (is_black(tr)) return Color(0.f);
        }
        return tr;
    }

    struct PlaneData {
        Vec3d point, normal;
        uint32_t geom;
        uint32_t flags;  ///< SurfaceFilter::mesh_flags(geom)
    };

    static Hit plane_hit(const PlaneData& p, float t) {
        Hit h;
        h.t = t;
        h.prim = 0;
        h.geom = p.geom;
        h.inst = kInvalidId;
        return h;
    }

    std::unique_ptr<Accelerator> m_inner;
    const SurfaceFilter& m_filter;
    std::vector<PlaneData> m_planes;
};

}  // namespace whitted
