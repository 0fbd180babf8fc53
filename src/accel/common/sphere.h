// Ray/sphere intersection shared by every backend (the in-house ones and Embree's user geometry),
// templated on the scalar type: float for the fast paths, double for the reference.
//
// The quadratic |o + t d - c|^2 = r^2, i.e. a t^2 + 2 b t + c0 = 0 with f = o - c,
// a = d.d, b = f.d, c0 = f.f - r^2, solved in the numerically stable form of Haines, Günther &
// Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, 2019,
// ch. 7):
//   - the discriminant b^2 - a c0 is computed as a (r^2 - |f - (f.d / a) d|^2): the squared
//     distance of the centre from the ray's line, instead of the difference of two large,
//     nearly equal squares (which loses everything for a small sphere far from the origin);
//   - the roots as q = -b - sign(b) sqrt(disc), t0 = c0 / q, t1 = q / a: the two terms of q have
//     the same sign, so there is no cancellation for the root near the origin.
// The centre is stored in double (Scene::Sphere) and f = o - c is formed in double, then rounded
// to T once; docs/accelerators.md gives the measured float-vs-double t error.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "accel/common/geometry.h"
#include "core/vecmath.h"

namespace whitted {

/// Both roots t0 <= t1 of the ray's line against the sphere (center, radius), in precision T.
/// Returns false when the line misses the sphere (or the input is degenerate: zero direction,
/// NaN). A tangent line gives t0 == t1.
template <typename T>
inline bool sphere_roots(const Vec3<T>& org, const Vec3<T>& dir, const Vec3d& center, double radius, T& t0, T& t1) {
    // f = o - c in double: the centre may lie far from the world origin.
    const Vec3<T> f(Vec3d(org) - center);
    const T r = T(radius);
    const T a = dot(dir, dir);
    const T b = dot(f, dir);
    // Discriminant from the distance of the centre to the line (Haines et al. 2019).
    const Vec3<T> perp = f - dir * (b / a);
    const T disc = a * (r * r - dot(perp, perp));
    if (!(disc >= T(0))) return false;  // also rejects NaN (a == 0)
    // Stable roots, no cancellation in q (Haines et al. 2019; Press et al., Numerical Recipes 5.6).
    const T q = -b - std::copysign(std::sqrt(disc), b);
    if (q == T(0)) {  // b == 0 and tangent: the double root -b / a is at the origin
        t0 = t1 = T(0);
        return true;
    }
    const T c0 = dot(f, f) - r * r;
    t0 = c0 / q;
    t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

/// Per-ray constants of the sphere test.
template <typename T>
struct SphereRay {
    Vec3<T> org, dir;
    SphereRay() = default;
    SphereRay(const Vec3<T>& o, const Vec3<T>& d) : org(o), dir(d) {}
};

/// World-space box of a sphere in precision T, rounded outwards (computed in double).
template <typename T>
inline Bounds3<T> sphere_bounds(const Vec3d& center, double radius) {
    return round_outwards<T>(Bounds3d{center - Vec3d(radius), center + Vec3d(radius)});
}

/// Conservative test whether the sphere's surface passes through the box [lo, hi] (Arvo 1990,
/// "A simple method for box-sphere intersection testing", with the farthest corner added so that
/// boxes entirely inside the sphere, which the surface does not reach, are skipped). The box is
/// enlarged by a small relative padding, as in triangle_overlaps_box.
template <typename T>
inline bool sphere_surface_overlaps_box(const Vec3d& center, double radius, const Vec3<T>& lo, const Vec3<T>& hi) {
    const double pad = 1e-5 * double(max_component(hi - lo)) + 1e-30;
    double near2 = 0.0, far2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double l = double(lo[k]) - pad, h = double(hi[k]) + pad, c = center[k];
        const double dn = c < l ? l - c : (c > h ? c - h : 0.0);
        const double df = std::max(std::fabs(c - l), std::fabs(c - h));
        near2 += dn * dn;
        far2 += df * df;
    }
    const double r2 = radius * radius;
    return near2 <= r2 * (1.0 + 1e-9) && far2 >= r2 * (1.0 - 1e-9);
}

}  // namespace whitted
