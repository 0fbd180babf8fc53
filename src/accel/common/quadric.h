// Ray/quadric intersection shared by every backend (the in-house ones and Embree's user
// geometry): cylinders, cones (truncated) and discs (Scene::Quadric), in double precision in the
// quadric's object space, whatever the backend's precision.
//
// The ray goes into object space through object_from_world (t is kept: the direction is not
// normalised), then its origin moves along the line to the point nearest the quadric's centre, so
// that the quadratic's coefficients are of the object's size however far away the ray starts
// (the cancellation of b^2 - ac that loses a far ray's hit is avoided as for spheres, Haines et
// al. 2019). The side x^2 + y^2 = R(z)^2, R(z) = r0 + k z, is the quadratic
//   a s^2 + 2 b s + c,  a = dx^2 + dy^2 - k^2 dz^2,  b = ox dx + oy dy - k dz R(oz),
//                       c = ox^2 + oy^2 - R(oz)^2,
// solved in the stable form q = -(b + sign(b) sqrt(b^2 - ac)), roots c / q and q / a (the first
// survives a = 0, a ray parallel to a cone's side line).
//   - Closed (caps): the solid is the slab 0 <= z <= height intersected with the inside of the
//     infinite (double) cone, F <= 0. The ray's interval in it is the intersection of its
//     interval in the slab and its interval inside F, so entry and exit are a max and a min of
//     the same numbers the side and the caps give: there is no gap at a rim for a ray to slip
//     through (watertight by construction), and every ray crosses the solid 0 or 2 times.
//   - Open: the side's roots whose z lies in [0, height].
//   - Disc: the plane z = 0 within inner <= r <= outer.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "accel/common/geometry.h"
#include "core/vecmath.h"
#include "scene/scene.h"

namespace whitted {

/// Object-space shape and inverse transform of a quadric, as the intersection test needs them,
/// with a world-space bound that rejects most missing lines before the transform: every point of
/// a cylinder or cone lies within `reach` of its axis line (axis_origin + s axis_dir).
struct QuadricShape {
    Mat4d object_from_world;            ///< Scene::Quadric's
    double r0 = 1, r1 = 1, height = 1;  ///< Scene::Quadric radius0, radius1, height
    double inner = 0;                   ///< discs: inner radius
    QuadricKind kind = QuadricKind::Cylinder;
    bool caps = false;
    Vec3d axis_origin{0.0}, axis_dir{0.0, 0.0, 1.0};  ///< world: the object's origin and unit +Z
    double reach = std::numeric_limits<double>::infinity();  ///< infinite: no bound (discs)

    QuadricShape() = default;
    explicit QuadricShape(const Quadric& q)
        : object_from_world(q.object_from_world), r0(q.radius0), r1(q.radius1), height(q.height),
          inner(q.inner_radius), kind(q.kind), caps(q.caps) {
        if (kind == QuadricKind::Disc) return;
        const Mat4d& m = q.world_from_object;
        const Vec3d c0{m(0, 0), m(1, 0), m(2, 0)}, c1{m(0, 1), m(1, 1), m(2, 1)}, c2{m(0, 2), m(1, 2), m(2, 2)};
        if (!(dot(c2, c2) > 0.0)) return;
        axis_origin = {m(0, 3), m(1, 3), m(2, 3)};
        axis_dir = normalize(c2);
        // A point x c0 + y c1 + z c2 (x^2 + y^2 <= r^2) is |x c0 + y c1| <= sigma r from the axis
        // line, sigma the largest singular value of [c0 c1] (any affine map, shears included).
        const double g00 = dot(c0, c0), g11 = dot(c1, c1), g01 = dot(c0, c1);
        const double half = 0.5 * (g00 - g11);
        const double sigma = std::sqrt(0.5 * (g00 + g11) + std::sqrt(half * half + g01 * g01));
        reach = sigma * std::max(r0, r1);
        if (!std::isfinite(reach)) reach = std::numeric_limits<double>::infinity();
    }

    /// True when the line o + t d passes farther than `reach` from the axis line (with a margin
    /// far above the rounding of this test): it cannot cross the shape. False when unsure (a
    /// line parallel to the axis, a disc).
    bool line_misses(const Vec3d& o, const Vec3d& d) const {
        const Vec3d n = cross(d, axis_dir);
        const double nn = dot(n, n);
        if (!(nn > 1e-12 * dot(d, d))) return false;  // (nearly) parallel: no bound from this
        const Vec3d w = o - axis_origin;
        const double wn = dot(w, n);
        const double limit = reach * (1.0 + 1e-9) + 1e-12 * (std::fabs(w.x) + std::fabs(w.y) + std::fabs(w.z));
        return wn * wn > limit * limit * nn;  // |w.n| / |n|, the lines' distance, beyond the limit
    }
};

namespace quadric_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// An interval [lo, hi] of the ray parameter (empty when lo > hi).
struct Span {
    double lo = kInf, hi = -kInf;
    bool empty() const { return !(lo <= hi); }
    double length() const { return hi - lo; }
};

inline Span intersect(const Span& a, const Span& b) { return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)}; }

/// The side's quadratic a s^2 + 2 b s + c about the re-centred origin o (see the top).
struct SideQuadratic {
    double a, b, c;
    SideQuadratic(const QuadricShape& q, const Vec3d& o, const Vec3d& d) {
        const double k = (q.r1 - q.r0) / q.height;
        const double r_o = q.r0 + k * o.z;
        a = d.x * d.x + d.y * d.y - k * k * d.z * d.z;
        b = o.x * d.x + o.y * d.y - k * d.z * r_o;
        c = o.x * o.x + o.y * o.y - r_o * r_o;
    }
    /// Real roots in ascending order (0, 1 or 2; a double root counts twice).
    int roots(double s[2]) const {
        const double disc = b * b - a * c;
        if (!(disc >= 0.0)) return 0;
        const double q = -(b + std::copysign(std::sqrt(disc), b));
        if (q == 0.0) {  // b = 0 and disc = 0: a s^2 + c with ac = 0
            if (a == 0.0) return 0;  // constant (c = 0: the line lies on the surface; count no crossing)
            s[0] = s[1] = 0.0;
            return 2;
        }
        s[0] = c / q;
        if (a == 0.0) return 1;
        s[1] = q / a;
        if (s[0] > s[1]) std::swap(s[0], s[1]);
        return 2;
    }
};

/// The ray's parameters inside the infinite cone (F <= 0): up to two spans.
inline int inside_spans(const SideQuadratic& f, Span out[2]) {
    double s[2];
    const int n = f.roots(s);
    if (f.a > 0.0) {
        if (n < 2) return 0;
        out[0] = {s[0], s[1]};
        return 1;
    }
    if (f.a < 0.0) {
        if (n < 2) {  // no real root: F < 0 along the whole line
            out[0] = {-kInf, kInf};
            return 1;
        }
        out[0] = {-kInf, s[0]};
        out[1] = {s[1], kInf};
        return 2;
    }
    if (f.b != 0.0) {  // linear: 2 b s + c <= 0
        const double r = -f.c / (2.0 * f.b);
        out[0] = f.b > 0.0 ? Span{-kInf, r} : Span{r, kInf};
        return 1;
    }
    if (f.c <= 0.0) {
        out[0] = {-kInf, kInf};
        return 1;
    }
    return 0;
}

}  // namespace quadric_detail

/// Every crossing of the quadric's surface by the ray's whole line, in ascending order of t
/// (0, 1 or 2 of them), in world-ray parameters: the caller keeps those in its (tnear, tfar]
/// (tnear >= 0). A disc's crossing clearly behind the origin (t < 0) is left out.
/// face[i] names the surface crossed (QuadricPoint::part: 0 the side or a disc, 1 the base cap,
/// 2 the top cap), decided by the same comparison that chose t, so a ray through a rim gets the
/// face it crossed. Degenerate input (zero direction, NaN) gives none.
inline int quadric_crossings(const QuadricShape& q, const Vec3d& world_org, const Vec3d& world_dir, double t[2],
                             uint8_t face[2]) {
    using namespace quadric_detail;
    if (q.kind == QuadricKind::Disc) {
        // The plane z = 0 is crossed at t = -o.z / d.z (object space keeps the world ray's t): behind
        // the origin when o.z and d.z have the same sign. Where o.z stands clear of its rounding,
        // no caller keeps that crossing: skip the transforms and the re-centring (a scene's ground
        // disc meets every ray that leaves upwards, shadow rays and mirror rays alike).
        const Mat4d& m = q.object_from_world;
        const double ox = m(2, 0) * world_org.x, oy = m(2, 1) * world_org.y, oz = m(2, 2) * world_org.z;
        const double o_z = ox + oy + oz + m(2, 3);
        const double d_z = m(2, 0) * world_dir.x + m(2, 1) * world_dir.y + m(2, 2) * world_dir.z;
        const double rounding = 1e-9 * (std::fabs(ox) + std::fabs(oy) + std::fabs(oz) + std::fabs(m(2, 3)));
        if (((o_z > 0.0 && d_z > 0.0) || (o_z < 0.0 && d_z < 0.0)) && std::fabs(o_z) > rounding) return 0;
    }
    if (q.line_misses(world_org, world_dir)) return 0;
    const Vec3d o0 = q.object_from_world.apply_point(world_org);
    const Vec3d d = q.object_from_world.apply_vector(world_dir);
    const double dd = dot(d, d);
    if (!(dd > 0.0) || !std::isfinite(dd)) return 0;
    // Re-centre: the origin moves to the line's point nearest the object's centre.
    const Vec3d centre{0.0, 0.0, q.kind == QuadricKind::Disc ? 0.0 : 0.5 * q.height};
    const double tc = dot(centre - o0, d) / dd;
    const Vec3d o = o0 + d * tc;
    if (!is_finite(o)) return 0;
    int n = 0;
    if (q.kind == QuadricKind::Disc) {
        if (d.z == 0.0) return 0;
        const double s = -o.z / d.z;
        const double x = o.x + s * d.x, y = o.y + s * d.y;
        const double r2 = x * x + y * y;
        if (!(r2 <= q.r0 * q.r0 && r2 >= q.inner * q.inner)) return 0;
        t[0] = tc + s;
        face[0] = 0;
        return 1;
    }
    const SideQuadratic f(q, o, d);
    if (q.caps) {
        // The slab 0 <= z <= height; which cap each of its ends is.
        Span slab{-kInf, kInf};
        uint8_t slab_face[2] = {1, 2};
        if (d.z != 0.0) {
            slab = {(0.0 - o.z) / d.z, (q.height - o.z) / d.z};
            if (slab.lo > slab.hi) {
                std::swap(slab.lo, slab.hi);
                std::swap(slab_face[0], slab_face[1]);
            }
        } else if (!(o.z >= 0.0 && o.z <= q.height)) {
            return 0;
        }
        Span pieces[2];
        const int m = inside_spans(f, pieces);
        Span best, piece;
        for (int i = 0; i < m; ++i) {
            const Span s = intersect(slab, pieces[i]);
            if (!s.empty() && (best.empty() || s.length() > best.length())) best = s, piece = pieces[i];
        }
        if (best.empty() || !std::isfinite(best.lo) || !std::isfinite(best.hi)) return 0;
        t[0] = tc + best.lo;
        t[1] = tc + best.hi;
        // A cap where the slab's end binds, the side where the cone's does (on an exact tie, the side).
        face[0] = best.lo > piece.lo ? slab_face[0] : 0;
        face[1] = best.hi < piece.hi ? slab_face[1] : 0;
        return 2;
    }
    double s[2];
    const int m = f.roots(s);
    for (int i = 0; i < m; ++i) {
        const double z = o.z + s[i] * d.z;
        if (z >= 0.0 && z <= q.height) {
            face[n] = 0;
            t[n++] = tc + s[i];
        }
    }
    return n;
}

/// World-space box of a quadric in precision T, rounded outwards (quadric_bounds in double,
/// padded by 1e-12 of its coordinates).
template <typename T>
inline Bounds3<T> quadric_bounds_t(const Quadric& q) {
    Bounds3d b = quadric_bounds(q);
    for (int k = 0; k < 3; ++k) {
        const double pad = 1e-12 * (std::fabs(b.lo[k]) + std::fabs(b.hi[k]));
        b.lo[k] -= pad;
        b.hi[k] += pad;
    }
    return round_outwards<T>(b);
}

}  // namespace whitted
