// The two ray queries as objects the in-house traversals report candidate hits to. They hold the
// SurfaceFilter semantics every backend must share with Embree (accelerator.h), so that a backend
// only has to find candidate triangles:
//   - ClosestQuery keeps the nearest accepted hit; accept() is asked only for meshes whose
//     mesh_flags() has kNeedsAccept.
//   - ShadowQuery stops at the first crossing of a mesh without filter flags (opaque), otherwise
//     collects the crossings; resolve() sorts them by t, removes duplicates per (geom, inst,
//     part) within 64 ulps of t (Embree's rule) and multiplies their transmittances. Sorting
//     makes the product independent of traversal order.
// A report's `part` tells the two crossings of one analytic sphere apart (0 = entering root,
// 1 = leaving root), so that a small transparent sphere far away counts twice even when both of
// its roots fall within the de-duplication window; triangles always report part 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "renderer/accel/accelerator.h"

namespace whitted {

/// Two crossings of one (geom, inst) closer than this many ulps of t are one crossing (as in
/// the Embree backend).
constexpr float kDedupUlps = 64.f;

/// The instance a traversal is currently inside, with its filter needs (for spheres: the sphere
/// being tested, inst = kInvalidId).
struct InstanceContext {
    uint32_t geom = kInvalidId;
    uint32_t inst = kInvalidId;
    uint32_t flags = 0;  ///< SurfaceFilter::mesh_flags(geom)
};

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

    /// A hit with tnear < t <= tmax. Returns true to end the whole traversal (never).
    bool report(T t, T u, T v, uint32_t prim, uint8_t /*part*/ = 0) {
        Hit h;
        h.t = float(t);
        h.u = float(u);
        h.v = float(v);
        h.prim = prim;
        h.geom = ctx.geom;
        h.inst = ctx.inst;
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
    uint8_t part;  ///< which root of a sphere (0 for triangles and planes)
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
        if (!(ctx.flags & (SurfaceFilter::kNeedsTransmittance | SurfaceFilter::kNeedsAccept))) {
            blocked = true;
            return true;
        }
        crossings.push_back({float(t), float(u), float(v), prim, ctx.geom, ctx.inst, part});
        return false;
    }

    /// The product of the distinct crossings' transmittances (exactly 0 when blocked).
    Color resolve() {
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
        for (size_t i = 0; i < crossings.size(); ++i) {
            const Crossing c = crossings[i];
            const float window = kDedupUlps * (std::nextafter(std::fabs(c.t), kInfinity) - std::fabs(c.t));
            bool duplicate = false;
            for (size_t k = 0; k < kept; ++k) {
                const Crossing& s = crossings[k];
                if (s.geom == c.geom && s.inst == c.inst && s.part == c.part && std::fabs(s.t - c.t) <= window) {
                    duplicate = true;
                    break;
                }
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
