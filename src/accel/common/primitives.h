// Primitive sets the in-house structures are built over, so that one BVH / grid / octree code
// serves both triangle meshes (object space, one per mesh) and the scene's analytic spheres
// and quadrics (world space, one set per scene). A primitive set P provides
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
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "accel/common/geometry.h"
#include "accel/common/quadric.h"
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

/// Outward-rounded k-DOP of a set of points (the diagonal projections round in T).
template <typename T, size_t N>
KdopVolume<T> points_kdop(const std::array<Vec3<T>, N>& points) {
    KdopVolume<T> d;
    for (int k = 0; k < kKdopSlabs; ++k) {
        d.lo[k] = std::numeric_limits<T>::infinity();
        d.hi[k] = -std::numeric_limits<T>::infinity();
        for (const Vec3<T>& p : points) {
            const T proj = kdop_project(k, p);
            const T err = k < 3 ? T(0) : rounding_gamma<T>(3) * (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z));
            d.lo[k] = std::min(d.lo[k], proj - err);
            d.hi[k] = std::max(d.hi[k], proj + err);
        }
    }
    return d;
}

/// Outward-rounded k-DOP of one triangle.
template <typename T>
KdopVolume<T> triangle_kdop(const TriangleVerts<T>& tri) {
    return points_kdop<T, 3>({tri.p0, tri.p1, tri.p2});
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

/// The scene's analytic primitives in world space: spheres (sphere_roots, Haines et al. 2019)
/// and quadrics (quadric_crossings: cylinders, cones, discs, in double in object space). Each
/// hit is reported with geom = its geometry id, inst = kInvalidId, prim = the face crossed (0 for
/// spheres; a quadric's QuadricPoint::part), u = v = 0, and the filter flags of that geometry; its
/// crossings in ascending t as parts 0 and 1 (for a sphere or a capped quadric: entering, leaving).
template <typename T>
class AnalyticPrims {
public:
    using RayData = SphereRay<T>;

    /// A sphere, or a quadric (geom >= the first quadric's id: centre and radius then bound it).
    struct Item {
        Vec3d center;
        double radius;
        uint32_t geom;   ///< Scene::sphere_geom_id(i) or Scene::quadric_geom_id(i)
        uint32_t flags;  ///< SurfaceFilter::mesh_flags(geom)
    };

    AnalyticPrims() = default;
    /// The spheres with a finite centre and a finite radius > 0, and the quadrics with a finite,
    /// invertible transform (others cannot be hit).
    AnalyticPrims(const Scene& scene, const SurfaceFilter& filter) : m_first_quadric(scene.quadric_geom_id(0)) {
        for (size_t i = 0; i < scene.spheres.size(); ++i) {
            const Sphere& s = scene.spheres[i];
            if (!is_finite(s.center) || !(s.radius > 0.0) || !std::isfinite(s.radius)) continue;
            const uint32_t geom = scene.sphere_geom_id(i);
            m_items.push_back({s.center, s.radius, geom, filter.mesh_flags(geom)});
        }
        m_quadrics.resize(scene.quadrics.size());
        for (size_t i = 0; i < scene.quadrics.size(); ++i) {
            const Quadric& q = scene.quadrics[i];
            if (!q.world_from_object.is_finite() || !q.object_from_world.is_finite() ||
                !(std::fabs(q.world_from_object.det3()) > 0.0))
                continue;
            const Bounds3d b = quadric_bounds(q);
            if (!is_finite(b.lo) || !is_finite(b.hi)) continue;
            m_quadrics[i] = {QuadricShape(q), quadric_bounds_t<T>(q)};
            const uint32_t geom = scene.quadric_geom_id(i);
            m_items.push_back({b.center(), 0.5 * length(b.diagonal()), geom, filter.mesh_flags(geom)});
        }
    }

    static RayData ray_data(const Vec3<T>& org, const Vec3<T>& dir) { return RayData(org, dir); }
    uint32_t size() const { return uint32_t(m_items.size()); }
    const Item& item(uint32_t i) const { return m_items[i]; }
    bool is_quadric(const Item& s) const { return s.geom >= m_first_quadric; }
    Bounds3<T> bounds(uint32_t i) const {
        const Item& s = m_items[i];
        return is_quadric(s) ? quadric(s).box : sphere_bounds<T>(s.center, s.radius);
    }
    bool overlaps_box(uint32_t i, const Vec3<T>& lo, const Vec3<T>& hi) const {
        const Item& s = m_items[i];
        if (!is_quadric(s)) return sphere_surface_overlaps_box(s.center, s.radius, lo, hi);
        // Conservative: the quadric's box touches the box.
        const Bounds3<T>& b = quadric(s).box;
        for (int k = 0; k < 3; ++k)
            if (b.hi[k] < lo[k] || b.lo[k] > hi[k]) return false;
        return true;
    }
    T max_distance2(uint32_t i, const Vec3<T>& c) const {
        // A quadric lies inside its bounding sphere (centre, radius) as a sphere in itself.
        const double d = length(m_items[i].center - Vec3d(c)) + m_items[i].radius;
        return T(d * d * (1.0 + 1e-12));
    }
    KdopVolume<T> kdop(uint32_t i) const {
        const Item& s = m_items[i];
        KdopVolume<T> d;
        if (is_quadric(s)) {  // the 8 corners of its box
            const Bounds3<T>& b = quadric(s).box;
            std::array<Vec3<T>, 8> corners;
            for (int c = 0; c < 8; ++c)
                corners[size_t(c)] = {(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
            return points_kdop<T, 8>(corners);
        }
        // Projection of the centre onto each normal n, +- r |n| (|n| = 1 or sqrt 3), in double,
        // widened by the float rounding bound of triangle_kdop.
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
    size_t bytes() const { return m_items.size() * sizeof(Item) + m_quadrics.size() * sizeof(QuadricEntry); }

    /// The item's crossings of the ray's line in ascending t (0, 1 or 2; the caller keeps those in
    /// its interval) and the face each crosses: a sphere's two roots (face 0), or a quadric's
    /// crossings (computed in double). kQuadric must be is_quadric(s): each kind gets its own code.
    template <bool kQuadric>
    int crossings(const Item& s, const Vec3<T>& org, const Vec3<T>& dir, T t[2], uint8_t face[2]) const {
        if constexpr (!kQuadric) {
            face[0] = face[1] = 0;
            return sphere_roots(org, dir, s.center, s.radius, t[0], t[1]) ? 2 : 0;
        } else {
            double td[2];
            const int n = quadric_crossings(quadric(s).shape, Vec3d(org), Vec3d(dir), td, face);
            for (int i = 0; i < n; ++i) t[i] = T(td[i]);
            return n;
        }
    }

    template <class Query>
    bool intersect(const RayData& r, uint32_t slot, uint32_t /*id*/, T tnear, Query& q) const {
        const Item& s = m_items[slot];
        return is_quadric(s) ? intersect_item<true>(s, r, tnear, q) : intersect_item<false>(s, r, tnear, q);
    }

private:
    struct QuadricEntry {
        QuadricShape shape;
        Bounds3<T> box;
    };
    const QuadricEntry& quadric(const Item& s) const { return m_quadrics[s.geom - m_first_quadric]; }

    template <bool kQuadric, class Query>
    bool intersect_item(const Item& s, const RayData& r, T tnear, Query& q) const {
        T t[2];
        uint8_t face[2];
        const int n = crossings<kQuadric>(s, r.org, r.dir, t, face);
        if (n == 0) return false;
        q.ctx = InstanceContext{s.geom, kInvalidId, s.flags};
        // Nearer crossing first; the farther one is still reported when the nearer one is outside
        // (tnear, tmax] (a ray from inside) or rejected by accept() (tmax did not shrink), and
        // always to a shadow query (both crossings count).
        for (int i = 0; i < n; ++i) {
            // A closest-hit query that took the first crossing does not take a second one that
            // rounds to the same t (a ray through a rim: the tie rule would pick the face with the
            // lower id, the one the ray leaves through).
            if constexpr (!Query::kAllHits)
                if (i == 1 && t[1] == t[0] && q.tmax == t[0]) break;
            if (t[i] > tnear && t[i] <= q.tmax && q.report(t[i], T(0), T(0), uint32_t(face[i]), uint8_t(i))) return true;
        }
        return false;
    }

    std::vector<Item> m_items;
    std::vector<QuadricEntry> m_quadrics;  ///< by quadric index (skipped ones stay default)
    uint32_t m_first_quadric = 0;          ///< Scene::quadric_geom_id(0)
};

}  // namespace whitted
