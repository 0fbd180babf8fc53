// Primitive sets the in-house structures are built over, so that one BVH / grid / octree code
// serves both triangle meshes (object space, one per mesh) and the scene's analytic spheres
// (world space, one set per scene). A primitive set P provides
//   using RayData = ...;                               per-ray constants of its intersection test
//   static RayData ray_data(const Vec3<T>& org, const Vec3<T>& dir);
//   uint32_t size() const;
//   Bounds3<T> bounds(uint32_t i) const;               conservative box
//   bool overlaps_box(uint32_t i, lo, hi) const;       conservative: never false for a touched box
//   T max_distance2(uint32_t i, const Vec3<T>& c) const;   squared distance of its farthest point
//   KdopVolume<T> kdop(uint32_t i) const;              outward-rounded 7-slab volume
//   void reorder(const std::vector<uint32_t>& order);  slot k then holds old primitive order[k]
//   template <class Q> bool intersect(const RayData&, uint32_t slot, uint32_t id, T tnear, Q&) const;
//     reports every hit in (tnear, q.tmax] of the primitive stored at `slot`, whose original
//     index is `id`, to q.report(...) and returns true as soon as report() does;
//   size_t bytes() const.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "accel/common/geometry.h"
#include "accel/common/queries.h"
#include "accel/common/sphere.h"
#include "scene/scene.h"

namespace whitted {

/// A triangle's three vertices in the precision T.
template <typename T>
struct TriangleVerts {
    Vec3<T> p0, p1, p2;
};

/// Object-space triangles of a mesh (index order), degenerate index ranges already validated by
/// the importer.
template <typename T>
std::vector<TriangleVerts<T>> mesh_triangles(const Mesh& mesh) {
    std::vector<TriangleVerts<T>> tris(mesh.triangle_count());
    for (size_t i = 0; i < tris.size(); ++i) {
        tris[i] = {Vec3<T>(mesh.positions[mesh.indices[3 * i]]), Vec3<T>(mesh.positions[mesh.indices[3 * i + 1]]),
                   Vec3<T>(mesh.positions[mesh.indices[3 * i + 2]])};
    }
    return tris;
}

template <typename T>
Bounds3<T> triangle_bounds(const TriangleVerts<T>& t) {
    Bounds3<T> b;
    b.extend(t.p0);
    b.extend(t.p1);
    b.extend(t.p2);
    return b;
}

/// Outward-rounded k-DOP of one triangle (the diagonal projections round in T).
template <typename T>
KdopVolume<T> triangle_kdop(const TriangleVerts<T>& tri) {
    KdopVolume<T> d;
    for (int k = 0; k < kKdopSlabs; ++k) {
        d.lo[k] = std::numeric_limits<T>::infinity();
        d.hi[k] = -std::numeric_limits<T>::infinity();
        for (const Vec3<T>& p : {tri.p0, tri.p1, tri.p2}) {
            const T proj = kdop_project(k, p);
            const T err = k < 3 ? T(0) : rounding_gamma<T>(3) * (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z));
            d.lo[k] = std::min(d.lo[k], proj - err);
            d.hi[k] = std::max(d.hi[k], proj + err);
        }
    }
    return d;
}

/// The triangles of one mesh, watertight test (Woop et al. 2013). Reports q.report(t, u, v, id).
template <typename T>
class TrianglePrims {
public:
    using RayData = WatertightRay<T>;

    explicit TrianglePrims(const Mesh& mesh) : m_tris(mesh_triangles<T>(mesh)) {}

    static RayData ray_data(const Vec3<T>& org, const Vec3<T>& dir) { return RayData(org, dir); }
    uint32_t size() const { return uint32_t(m_tris.size()); }
    const TriangleVerts<T>& triangle(uint32_t i) const { return m_tris[i]; }
    Bounds3<T> bounds(uint32_t i) const { return triangle_bounds(m_tris[i]); }
    bool overlaps_box(uint32_t i, const Vec3<T>& lo, const Vec3<T>& hi) const {
        return triangle_overlaps_box(lo, hi, m_tris[i].p0, m_tris[i].p1, m_tris[i].p2);
    }
    T max_distance2(uint32_t i, const Vec3<T>& c) const {
        const TriangleVerts<T>& t = m_tris[i];
        return std::max({dot(t.p0 - c, t.p0 - c), dot(t.p1 - c, t.p1 - c), dot(t.p2 - c, t.p2 - c)});
    }
    KdopVolume<T> kdop(uint32_t i) const { return triangle_kdop(m_tris[i]); }
    void reorder(const std::vector<uint32_t>& order) {
        std::vector<TriangleVerts<T>> sorted(order.size());
        for (size_t k = 0; k < order.size(); ++k) sorted[k] = m_tris[order[k]];
        m_tris = std::move(sorted);
    }
    size_t bytes() const { return m_tris.size() * sizeof(m_tris[0]); }

    template <class Query>
    bool intersect(const RayData& r, uint32_t slot, uint32_t id, T tnear, Query& q) const {
        const TriangleVerts<T>& tri = m_tris[slot];
        T t, u, v;
        return intersect_triangle(r, tri.p0, tri.p1, tri.p2, tnear, q.tmax, t, u, v) && q.report(t, u, v, id);
    }

private:
    std::vector<TriangleVerts<T>> m_tris;
};

/// The scene's analytic spheres in world space (sphere_roots, Haines et al. 2019). Each hit is
/// reported with geom = Scene::sphere_geom_id(i), inst = kInvalidId, prim = 0, u = v = 0, and the
/// filter flags of that geometry; the entering root as part 0, the leaving root as part 1.
template <typename T>
class SpherePrims {
public:
    using RayData = SphereRay<T>;

    struct Item {
        Vec3d center;
        double radius;
        uint32_t geom;   ///< Scene::sphere_geom_id(i)
        uint32_t flags;  ///< SurfaceFilter::mesh_flags(geom)
    };

    SpherePrims() = default;
    /// The spheres with a finite centre and a finite radius > 0 (others cannot be hit).
    SpherePrims(const Scene& scene, const SurfaceFilter& filter) {
        for (size_t i = 0; i < scene.spheres.size(); ++i) {
            const Sphere& s = scene.spheres[i];
            if (!is_finite(s.center) || !(s.radius > 0.0) || !std::isfinite(s.radius)) continue;
            const uint32_t geom = scene.sphere_geom_id(i);
            m_items.push_back({s.center, s.radius, geom, filter.mesh_flags(geom)});
        }
    }

    static RayData ray_data(const Vec3<T>& org, const Vec3<T>& dir) { return RayData(org, dir); }
    uint32_t size() const { return uint32_t(m_items.size()); }
    const Item& item(uint32_t i) const { return m_items[i]; }
    Bounds3<T> bounds(uint32_t i) const { return sphere_bounds<T>(m_items[i].center, m_items[i].radius); }
    bool overlaps_box(uint32_t i, const Vec3<T>& lo, const Vec3<T>& hi) const {
        return sphere_surface_overlaps_box(m_items[i].center, m_items[i].radius, lo, hi);
    }
    T max_distance2(uint32_t i, const Vec3<T>& c) const {
        const double d = length(m_items[i].center - Vec3d(c)) + m_items[i].radius;
        return T(d * d * (1.0 + 1e-12));
    }
    KdopVolume<T> kdop(uint32_t i) const {
        // Projection of the centre onto each normal n, +- r |n| (|n| = 1 or sqrt 3), in double,
        // widened by the float rounding bound of triangle_kdop.
        const Item& s = m_items[i];
        KdopVolume<T> d;
        const double abs_sum = std::fabs(s.center.x) + std::fabs(s.center.y) + std::fabs(s.center.z);
        for (int k = 0; k < kKdopSlabs; ++k) {
            const double proj = kdop_project(k, s.center);
            const double reach = s.radius * (k < 3 ? 1.0 : std::sqrt(3.0)) * (1.0 + 1e-12);
            const double err = k < 3 ? 0.0 : double(rounding_gamma<T>(3)) * abs_sum;
            d.lo[k] = std::nextafter(T(proj - reach - err), -std::numeric_limits<T>::infinity());
            d.hi[k] = std::nextafter(T(proj + reach + err), std::numeric_limits<T>::infinity());
        }
        return d;
    }
    void reorder(const std::vector<uint32_t>& order) {
        std::vector<Item> sorted(order.size());
        for (size_t k = 0; k < order.size(); ++k) sorted[k] = m_items[order[k]];
        m_items = std::move(sorted);
    }
    size_t bytes() const { return m_items.size() * sizeof(Item); }

    template <class Query>
    bool intersect(const RayData& r, uint32_t slot, uint32_t /*id*/, T tnear, Query& q) const {
        const Item& s = m_items[slot];
        T t0, t1;
        if (!sphere_roots(r.org, r.dir, s.center, s.radius, t0, t1)) return false;
        q.ctx = InstanceContext{s.geom, kInvalidId, s.flags};
        // Nearer root first; the farther one is still reported when the nearer one is outside
        // (tnear, tmax] (a ray from inside) or rejected by accept() (tmax did not shrink), and
        // always to a shadow query (both crossings count).
        if (t0 > tnear && t0 <= q.tmax && q.report(t0, T(0), T(0), 0u, uint8_t(0))) return true;
        return t1 > tnear && t1 <= q.tmax && q.report(t1, T(0), T(0), 0u, uint8_t(1));
    }

private:
    std::vector<Item> m_items;
};

}  // namespace whitted
