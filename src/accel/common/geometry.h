// Geometric kernels shared by the in-house backends, templated on the scalar type (float for the
// fast paths, double for the reference): the watertight ray/triangle test (Woop, Benthin & Wald
// 2013), the conservative ray/box slab test (Ize 2013), ray/sphere and ray/k-DOP bounding-volume
// tests, and the triangle/box overlap test used to bin triangles into cells (Akenine-Möller 2001).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "accel/accelerator.h"
#include "accel/common/simd.h"
#include "core/vecmath.h"

namespace whitted {

/// gamma(n) = n eps / (1 - n eps): the bound on relative rounding error of n operations (pbrt).
template <typename T>
constexpr T rounding_gamma(int n) {
    constexpr T eps = std::numeric_limits<T>::epsilon() * T(0.5);
    return (T(n) * eps) / (T(1) - T(n) * eps);
}

/// True for rays every backend traces: finite origin and direction, non-zero direction, a
/// non-empty [tnear, tfar] (tfar may be +inf). Other rays (NaN, zero direction) miss everything.
/// Branch-free (the packet backends test every lane of every packet): x - x is 0 for finite x and
/// NaN for an infinity or NaN, and a sum with a NaN is NaN; a NaN tfar fails tnear <= tfar.
inline bool ray_is_traceable(const Ray& r) {
    const float finite = (r.org.x - r.org.x) + (r.org.y - r.org.y) + (r.org.z - r.org.z) + (r.dir.x - r.dir.x) +
                         (r.dir.y - r.dir.y) + (r.dir.z - r.dir.z) + (r.tnear - r.tnear);
    const float length = std::fabs(r.dir.x) + std::fabs(r.dir.y) + std::fabs(r.dir.z);
    return (finite == 0.f) & (length > 0.f) & (r.tnear <= r.tfar);
}

/// A double-precision box in precision T, rounded outwards (never smaller than `b`).
template <typename T>
inline Bounds3<T> round_outwards(const Bounds3d& b) {
    Bounds3<T> out;
    for (int k = 0; k < 3; ++k) {
        T lo = T(b.lo[k]), hi = T(b.hi[k]);
        if (double(lo) > b.lo[k]) lo = std::nextafter(lo, -std::numeric_limits<T>::infinity());
        if (double(hi) < b.hi[k]) hi = std::nextafter(hi, std::numeric_limits<T>::infinity());
        out.lo[k] = lo;
        out.hi[k] = hi;
    }
    return out;
}

// ---------------------------------------------------------------------------------------------
// Watertight ray/triangle intersection (Woop, Benthin & Wald 2013, JCGT 2(1))

/// Per-ray constants of the watertight test: the axis permutation and shear that map the ray
/// direction onto +z, so that the three edge functions are evaluated in a common 2D frame and a
/// ray through a shared edge or vertex hits at least one of the triangles sharing it.
template <typename T>
struct WatertightRay {
    Vec3<T> org;
    int kx = 0, ky = 1, kz = 2;
    T sx = 0, sy = 0, sz = 1;

    WatertightRay() = default;
    WatertightRay(const Vec3<T>& o, const Vec3<T>& d) : org(o) {
        // The dimension where the direction is largest becomes z.
        const T ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
        kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
        kx = kz == 2 ? 0 : kz + 1;
        ky = kx == 2 ? 0 : kx + 1;
        // Swap x and y when z points backwards to keep the winding (and so the sign of det).
        if (d[kz] < T(0)) std::swap(kx, ky);
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        sz = T(1) / d[kz];
    }
};

/// Component k of v by address: Vec3's operator[] branches, which is slow when k is only known
/// at run time (the permutation below).
template <typename T>
inline T component(const Vec3<T>& v, int k) {
    static_assert(sizeof(Vec3<T>) == 3 * sizeof(T) && std::is_standard_layout_v<Vec3<T>>);
    return (&v.x)[k];
}

/// Tests the triangle (p0, p1, p2) against the ray; on a hit with tnear < t <= tfar (Embree's
/// interval) writes t and the barycentrics u (of p1) and v (of p2). Edge functions that come out
/// exactly 0 in float are recomputed in double, as the paper prescribes.
template <typename T>
inline bool intersect_triangle(const WatertightRay<T>& r, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                               T tnear, T tfar, T& t_out, T& u_out, T& v_out) {
    // Vertices relative to the ray origin, then sheared and permuted so the ray is +z.
    const Vec3<T> a = p0 - r.org, b = p1 - r.org, c = p2 - r.org;
    const T a_z = component(a, r.kz), b_z = component(b, r.kz), c_z = component(c, r.kz);
    const T ax = component(a, r.kx) - r.sx * a_z, ay = component(a, r.ky) - r.sy * a_z;
    const T bx = component(b, r.kx) - r.sx * b_z, by = component(b, r.ky) - r.sy * b_z;
    const T cx = component(c, r.kx) - r.sx * c_z, cy = component(c, r.ky) - r.sy * c_z;
    // Scaled barycentrics from the 2D edge functions.
    T e0 = cx * by - cy * bx;
    T e1 = ax * cy - ay * cx;
    T e2 = bx * ay - by * ax;
    if constexpr (std::is_same_v<T, float>) {
        if (e0 == 0.f || e1 == 0.f || e2 == 0.f) {
            e0 = float(double(cx) * double(by) - double(cy) * double(bx));
            e1 = float(double(ax) * double(cy) - double(ay) * double(cx));
            e2 = float(double(bx) * double(ay) - double(by) * double(ax));
        }
    }
    if ((e0 < T(0) || e1 < T(0) || e2 < T(0)) && (e0 > T(0) || e1 > T(0) || e2 > T(0))) return false;
    const T det = e0 + e1 + e2;
    if (det == T(0)) return false;
    // Distance: the sheared z coordinates interpolated with the scaled barycentrics.
    const T az = r.sz * a_z, bz = r.sz * b_z, cz = r.sz * c_z;
    const T t_scaled = e0 * az + e1 * bz + e2 * cz;
    const T inv_det = T(1) / det;
    const T t = t_scaled * inv_det;
    if (!(t > tnear && t <= tfar)) return false;
    t_out = t;
    u_out = e1 * inv_det;
    v_out = e2 * inv_det;
    return true;
}

// ---------------------------------------------------------------------------------------------
// Bounding-volume tests. Each returns the entry distance of [tmin, tmax] into the volume, or
// +infinity for a miss; they are conservative: they never reject a volume the ray enters.

/// Per-ray constants for slab tests: the reciprocal direction and, per axis, whether the near
/// plane is the upper one (the sign bit of the direction, so -0 counts as negative).
template <typename T>
struct SlabRay {
    Vec3<T> org, dir, inv_dir;
    bool neg[3] = {false, false, false};
    T t_slack = 0;  ///< absolute enlargement of tmax in culling tests (see cull_slack)
    SlabRay() = default;
    /// `extent` bounds the absolute coordinates of everything the structure holds (0 = no slack).
    SlabRay(const Vec3<T>& o, const Vec3<T>& d, T extent = 0)
        : org(o), dir(d), inv_dir(T(1) / d.x, T(1) / d.y, T(1) / d.z) {
        for (int k = 0; k < 3; ++k) neg[k] = std::signbit(d[k]);
        if (extent > 0) t_slack = cull_slack(o, d, extent);
    }
    /// Absolute error bound of a primitive test's t along this ray: the watertight triangle test
    /// (and the sphere quadratic) compute t from vertex - origin differences, so its error scales
    /// with max|p - o| / max|d_k| (the shear's dominant axis), not with t itself. A hit at a small
    /// t far from the origin can therefore come out below the entry distance of a box it lies on
    /// (a flat floor's box, a ray with tfar exactly at its hit): culling tests compare against
    /// tmax * kRayTmaxScale + t_slack so rounding never culls a box holding an accepted hit.
    static T cull_slack(const Vec3<T>& o, const Vec3<T>& d, T extent) {
        const T o_max = std::max(std::fabs(o.x), std::max(std::fabs(o.y), std::fabs(o.z)));
        const T d_max = std::max(std::fabs(d.x), std::max(std::fabs(d.y), std::fabs(d.z)));
        const T s = T(32) * std::numeric_limits<T>::epsilon() * (o_max + extent) / d_max;
        return std::isfinite(s) ? s : T(0);
    }
};

/// Largest absolute coordinate of a box (the `extent` of SlabRay).
template <typename T>
inline T abs_extent(const Vec3<T>& lo, const Vec3<T>& hi) {
    T e = 0;
    for (int k = 0; k < 3; ++k) e = std::max(e, std::max(std::fabs(lo[k]), std::fabs(hi[k])));
    return std::isfinite(e) ? e : T(0);
}

/// Enlargement of a slab exit distance that absorbs the rounding of (p - o) * inv_d (Ize 2013).
template <typename T>
constexpr T kSlabExitScale = T(1) + T(2) * rounding_gamma<T>(3);

/// Enlargement of the ray's current tmax in volume tests: a hit lying on a box face has a t
/// (from the triangle test, a few ulps off) that the box's entry distance (rounded the other way)
/// may exceed; without the slack a ray whose tfar is exactly its hit could cull that box.
template <typename T>
constexpr T kRayTmaxScale = T(1) + T(4) * rounding_gamma<T>(8);

/// Robust slab test (Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2)). The near and far plane
/// of each slab are chosen by the sign bit of the direction (Williams et al. 2005), so a zero
/// component (+0 or -0) yields -inf/+inf for an origin inside the slab and +inf/-inf outside;
/// an origin exactly on a plane gives 0 * inf = NaN, which the comparisons below ignore (the ray
/// lies in the closed slab). The exit distance is enlarged by 1 + 2 gamma(3), so rounding can
/// never cull a box the ray touches.
/// Always inlined, axes written out: it is the inner loop of every binary tree (the two-level
/// top level over instances included).
template <typename T>
WHITTED_ALWAYS_INLINE T slab_entry(const SlabRay<T>& r, const Vec3<T>& lo, const Vec3<T>& hi, T tmin, T tmax) {
    tmax = tmax * kRayTmaxScale<T> + r.t_slack;
    auto axis = [&](T org, T inv_dir, bool neg, T l, T h) WHITTED_ALWAYS_INLINE_LAMBDA {
        const T t_near = ((neg ? h : l) - org) * inv_dir;
        const T t_far = ((neg ? l : h) - org) * inv_dir * kSlabExitScale<T>;
        tmin = t_near > tmin ? t_near : tmin;  // NaN compares false: no restriction
        tmax = t_far < tmax ? t_far : tmax;
    };
    axis(r.org.x, r.inv_dir.x, r.neg[0], lo.x, hi.x);
    axis(r.org.y, r.inv_dir.y, r.neg[1], lo.y, hi.y);
    axis(r.org.z, r.inv_dir.z, r.neg[2], lo.z, hi.z);
    return tmin <= tmax ? tmin : std::numeric_limits<T>::infinity();
}

/// Axis-aligned bounding box volume.
template <typename T>
struct AabbVolume {
    Vec3<T> lo, hi;
    static constexpr const char* kName = "aabb";
};

template <typename T>
WHITTED_ALWAYS_INLINE T volume_entry(const SlabRay<T>& r, const AabbVolume<T>& v, T tmin, T tmax) {
    return slab_entry(r, v.lo, v.hi, tmin, tmax);
}

/// Bounding sphere volume (Whitted's (1980) bounding volume), radius enlarged at build time so
/// that the float test stays conservative.
template <typename T>
struct SphereVolume {
    Vec3<T> center;
    T radius = 0;
    static constexpr const char* kName = "sphere";
};

template <typename T>
inline T volume_entry(const SlabRay<T>& r, const SphereVolume<T>& s, T tmin, T tmax) {
    // Closest approach of the (non-normalized) ray to the centre, then the half chord.
    const Vec3<T> oc = s.center - r.org;
    const T dd = dot(r.dir, r.dir);
    const T tc = dot(oc, r.dir) / dd;
    const Vec3<T> perp = oc - r.dir * tc;
    const T r2 = s.radius * s.radius;
    const T p2 = dot(perp, perp);
    if (!(p2 <= r2)) return std::numeric_limits<T>::infinity();
    const T half = std::sqrt((r2 - p2) / dd) * (T(1) + T(8) * rounding_gamma<T>(1));
    const T slack = T(8) * rounding_gamma<T>(1) * std::fabs(tc);
    const T t0 = std::max(tmin, tc - half - slack);
    const T t1 = std::min(tmax * kRayTmaxScale<T> + r.t_slack, tc + half + slack);
    return t0 <= t1 ? t0 : std::numeric_limits<T>::infinity();
}

/// Kay-Kajiya slab volume with 7 normals (Kay & Kajiya 1986): the 3 axes and the 4 diagonals of
/// the cube. Slab k holds the triangles' projections onto kKdopNormals[k] in [lo[k], hi[k]].
constexpr int kKdopSlabs = 7;
inline constexpr int kKdopNormals[kKdopSlabs][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1},
                                                    {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};

template <typename T>
inline T kdop_project(int k, const Vec3<T>& p) {
    return T(kKdopNormals[k][0]) * p.x + T(kKdopNormals[k][1]) * p.y + T(kKdopNormals[k][2]) * p.z;
}

template <typename T>
struct KdopVolume {
    T lo[kKdopSlabs], hi[kKdopSlabs];
    static constexpr const char* kName = "kdop";
};

/// Per-ray constants of the k-DOP test: origin and direction projected onto the 7 normals, and
/// the origin projection's rounding bound (the diagonal projections are not exact in float).
template <typename T>
struct KdopRay {
    T org[kKdopSlabs], inv_dir[kKdopSlabs], org_err[kKdopSlabs];
    bool neg[kKdopSlabs];
    T t_slack = 0;  ///< as SlabRay::t_slack
    KdopRay() = default;
    explicit KdopRay(const SlabRay<T>& r) : t_slack(r.t_slack) {
        const T abs_sum = std::fabs(r.org.x) + std::fabs(r.org.y) + std::fabs(r.org.z);
        for (int k = 0; k < kKdopSlabs; ++k) {
            const T d = kdop_project(k, r.dir);
            org[k] = kdop_project(k, r.org);
            inv_dir[k] = T(1) / d;
            neg[k] = std::signbit(d);
            org_err[k] = k < 3 ? T(0) : rounding_gamma<T>(3) * abs_sum;
        }
    }
};

template <typename T>
inline T volume_entry(const KdopRay<T>& r, const KdopVolume<T>& v, T tmin, T tmax) {
    constexpr T grow = T(1) + T(4) * rounding_gamma<T>(5);
    tmax = tmax * kRayTmaxScale<T> + r.t_slack;
    for (int k = 0; k < kKdopSlabs; ++k) {
        // Same plane selection and NaN rule as slab_entry, slabs widened by the projection error.
        const T lo = v.lo[k] - r.org_err[k], hi = v.hi[k] + r.org_err[k];
        const T t_near = ((r.neg[k] ? hi : lo) - r.org[k]) * r.inv_dir[k];
        const T t_far = ((r.neg[k] ? lo : hi) - r.org[k]) * r.inv_dir[k] * grow;
        tmin = t_near > tmin ? t_near : tmin;
        tmax = t_far < tmax ? t_far : tmax;
    }
    return tmin <= tmax ? tmin : std::numeric_limits<T>::infinity();
}

// ---------------------------------------------------------------------------------------------
// Triangle/box overlap (separating axis test, Akenine-Möller 2001), made conservative by
// enlarging the box slightly: it may report an overlap that is not there, never the reverse.

template <typename T>
inline bool triangle_overlaps_box(const Vec3<T>& lo, const Vec3<T>& hi, const Vec3<T>& p0, const Vec3<T>& p1,
                                  const Vec3<T>& p2) {
    const Vec3<T> c = (lo + hi) * T(0.5);
    const Vec3<T> diag = hi - lo;
    const T pad = T(1e-5) * max_component(diag) + T(16) * std::numeric_limits<T>::min();
    const Vec3<T> h = diag * T(0.5) + Vec3<T>(pad);
    const Vec3<T> v0 = p0 - c, v1 = p1 - c, v2 = p2 - c;
    // The three box face normals.
    for (int k = 0; k < 3; ++k) {
        const T mn = std::min({v0[k], v1[k], v2[k]}), mx = std::max({v0[k], v1[k], v2[k]});
        if (mn > h[k] || mx < -h[k]) return false;
    }
    // The triangle normal.
    const Vec3<T> e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
    const Vec3<T> n = cross(e0, e1);
    {
        const T rad = h.x * std::fabs(n.x) + h.y * std::fabs(n.y) + h.z * std::fabs(n.z);
        const T d = dot(n, v0);
        if (std::fabs(d) > rad * (T(1) + T(1e-4))) return false;
    }
    // The nine edge x axis cross products.
    const Vec3<T> edges[3] = {e0, e1, e2};
    const Vec3<T> verts[3] = {v0, v1, v2};
    for (const Vec3<T>& e : edges)
        for (int k = 0; k < 3; ++k) {
            Vec3<T> axis(T(0));
            // axis = unit_k x e
            if (k == 0) axis = {T(0), -e.z, e.y};
            if (k == 1) axis = {e.z, T(0), -e.x};
            if (k == 2) axis = {-e.y, e.x, T(0)};
            T mn = std::numeric_limits<T>::infinity(), mx = -std::numeric_limits<T>::infinity();
            for (const Vec3<T>& v : verts) {
                const T p = dot(axis, v);
                mn = std::min(mn, p);
                mx = std::max(mx, p);
            }
            const T rad = h.x * std::fabs(axis.x) + h.y * std::fabs(axis.y) + h.z * std::fabs(axis.z);
            const T slack = T(1e-4) * (rad + std::max(std::fabs(mn), std::fabs(mx)));
            if (mn > rad + slack || mx < -rad - slack) return false;
        }
    return true;
}

}  // namespace whitted
