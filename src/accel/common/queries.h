// The two ray queries as objects the in-house traversals report candidate hits to. They hold the
// SurfaceFilter semantics every backend must share with Embree (accelerator.h), so that a backend
// only has to find candidate triangles:
//   - ClosestQuery keeps the nearest accepted hit (exact ties: tie_precedes()); accept() is asked
//     only for meshes whose mesh_flags() has kNeedsAccept.
//   - ShadowQuery stops at the first crossing of a mesh without kNeedsTransmittance (opaque to
//     shadow rays; kNeedsAccept plays no part in shadow queries, accelerator.h), otherwise
//     collects the crossings; resolve() sorts them by t, removes duplicates per (geom, inst,
//     part) within the window of same_crossing() (Embree's rule too) and multiplies their
//     transmittances. Sorting makes the product independent of traversal order.
// A report's `part` tells the two crossings of one analytic sphere apart (0 = entering root,
// 1 = leaving root), so that a small transparent sphere far away counts twice even when both of
// its roots fall within the de-duplication window; triangles always report part 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "accel/accelerator.h"

namespace whitted {

/// Two crossings of one (geom, inst) closer than this many ulps of t, at normal incidence, are
/// one crossing (as in the Embree backend).
constexpr float kDedupUlps = 64.f;

/// Largest factor by which the de-duplication window widens at grazing incidence: 1/|cos| is
/// clamped to it (|cos| < 1/1024, beyond 89.94 degrees, counts as 1/1024).
constexpr float kMaxDedupScale = 1024.f;

/// |cos| of the angle between a crossing's geometric normal and the ray direction (both of any
/// length, in one space); 1 when either is degenerate.
template <typename T>
inline float crossing_cosine(const Vec3<T>& ng, const Vec3<T>& dir) {
    const float c = float(std::fabs(dot(ng, dir)) / std::sqrt(dot(ng, ng) * dot(dir, dir)));
    return c > 0.f && c <= 1.f ? c : 1.f;
}

/// Whether two crossings of one surface (at ta, tb with |cos| ca, cb) are one. A triangle's t
/// carries an error that grows as 1/|cos| of the incidence (its projection onto the plane normal
/// to the ray is thin), so two triangles reporting one crossing, e.g. at a shared edge, differ by
/// more than kDedupUlps ulps at grazing angles: the window is kDedupUlps ulps of t divided by the
/// smaller |cos| of the two, at most kMaxDedupScale times wider. Measured along the normal the
/// window stays kDedupUlps ulps, so distinct sheets of one mesh are kept apart as well at grazing
/// incidence as at normal incidence (docs/numerical-stability.md).
inline bool same_crossing(float ta, float ca, float tb, float cb) {
    const float t = std::max(std::fabs(ta), std::fabs(tb));
    const float ulp = std::nextafter(t, kInfinity) - t;
    const float scale = 1.f / std::max(std::min(ca, cb), 1.f / kMaxDedupScale);
    return std::fabs(ta - tb) <= kDedupUlps * ulp * scale;
}

/// The instance a traversal is currently inside, with its filter needs (for spheres: the sphere
/// being tested, inst = kInvalidId).
struct InstanceContext {
    uint32_t geom = kInvalidId;
    uint32_t inst = kInvalidId;
    uint32_t flags = 0;  ///< SurfaceFilter::mesh_flags(geom)
};

/// The tie rule of every in-house closest-hit query: of two accepted hits at exactly the same t,
/// the one with the smaller (instance, geometry, primitive) wins, so the answer does not depend on
/// the order a traversal (single ray, batch, BVH child order, grid cell walk) meets them in.
inline bool tie_precedes(const Hit& a, const Hit& b) {
    if (a.inst != b.inst) return a.inst < b.inst;
    if (a.geom != b.geom) return a.geom < b.geom;
    return a.prim < b.prim;
}

/// Closest-hit query. T is the precision the backend computes t in.
template <typename T>
struct ClosestQuery {
    static constexpr bool kAllHits = false;
    const SurfaceFilter& filter;
    const Ray& ray;       ///< world-space ray as given by the caller (passed to accept())
    RayKind kind;
    T tmax;               ///< current upper bound: ray.tfar, then the best hit's t
    Hit best;
    InstanceContext ctx;

    ClosestQuery(const SurfaceFilter& f, const Ray& r, RayKind k) : filter(f), ray(r), kind(k), tmax(T(r.tfar)) {}

    /// A hit with tnear < t <= tmax. Returns true to end the whole traversal (never). At t equal
    /// to the best hit's, tie_precedes() decides.
    bool report(T t, T u, T v, uint32_t prim, uint8_t /*part*/ = 0) {
        Hit h;
        h.t = float(t);
        h.u = float(u);
        h.v = float(v);
        h.prim = prim;
        h.geom = ctx.geom;
        h.inst = ctx.inst;
        if (t == tmax && best.valid() && !tie_precedes(h, best)) [[unlikely]] return false;
        if ((ctx.flags & SurfaceFilter::kNeedsAccept) && !filter.accept(ray, h, kind)) return false;
        best = h;
        tmax = t;
        return false;
    }
};

/// One surface crossing of a shadow segment.
struct Crossing {
    float t, u, v;
    uint32_t prim, geom, inst;
    uint8_t part;        ///< which root of a sphere (0 for triangles and planes)
    float cosine = -1.f; ///< crossing_cosine(), computed by resolve() when needed (-1: not yet)
};

/// Transmittance query: all crossings in (tnear, tfar].
template <typename T>
struct ShadowQuery {
    static constexpr bool kAllHits = true;
    const SurfaceFilter& filter;
    const Ray& ray;
    T tmax;               ///< constant: ray.tfar
    bool blocked = false;
    InstanceContext ctx;
    std::vector<Crossing>& crossings;  ///< scratch owned by the caller (thread-local)

    ShadowQuery(const SurfaceFilter& f, const Ray& r, std::vector<Crossing>& scratch)
        : filter(f), ray(r), tmax(T(r.tfar)), crossings(scratch) {
        crossings.clear();
    }

    /// A hit with tnear < t <= tfar. Returns true once an opaque surface ends the query.
    bool report(T t, T u, T v, uint32_t prim, uint8_t part = 0) {
        if (!(ctx.flags & SurfaceFilter::kNeedsTransmittance)) {
            blocked = true;
            return true;
        }
        crossings.push_back({float(t), float(u), float(v), prim, ctx.geom, ctx.inst, part});
        return false;
    }

    /// The product of the distinct crossings' transmittances (exactly 0 when blocked).
    /// `cosine_of(c)` gives crossing_cosine() of a crossing; it is asked only for the pairs of one
    /// surface too far apart in t to be one crossing at normal incidence.
    template <class CosineOf>
    Color resolve(const CosineOf& cosine_of) {
        if (blocked) return Color(0.f);
        std::sort(crossings.begin(), crossings.end(), [](const Crossing& a, const Crossing& b) {
            if (a.t != b.t) return a.t < b.t;
            if (a.geom != b.geom) return a.geom < b.geom;
            if (a.inst != b.inst) return a.inst < b.inst;
            if (a.part != b.part) return a.part < b.part;
            return a.prim < b.prim;
        });
        Color tr(1.f);
        size_t kept = 0;  // crossings[0, kept) are the distinct ones so far
        auto cosine = [&](Crossing& x) {
            if (x.cosine < 0.f) x.cosine = cosine_of(x);
            return x.cosine;
        };
        for (size_t i = 0; i < crossings.size(); ++i) {
            Crossing c = crossings[i];
            bool duplicate = false;
            for (size_t k = 0; k < kept && !duplicate; ++k) {
                Crossing& s = crossings[k];
                if (s.geom != c.geom || s.inst != c.inst || s.part != c.part) continue;
                // At normal incidence first (cos 1): the cosines are computed only when that fails.
                duplicate = same_crossing(s.t, 1.f, c.t, 1.f) ||
                            (same_crossing(s.t, 1.f / kMaxDedupScale, c.t, 1.f / kMaxDedupScale) &&
                             same_crossing(s.t, cosine(s), c.t, cosine(c)));
            }
            if (duplicate) continue;
            crossings[kept++] = c;
            Hit h;
            h.t = c.t;
            h.u = c.u;
            h.v = c.v;
            h.prim = c.prim;
            h.geom = c.geom;
            h.inst = c.inst;
            tr *= filter.transmittance(ray, h);
            if (is_black(tr)) return Color(0.f);
        }
        return tr;
    }
};

}  // namespace whitted
