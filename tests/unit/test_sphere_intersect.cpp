// The ray/sphere kernel (src/accel/common/sphere.h) against the closed form in long double,
// in float and double, over ray families that stress it: from outside, from inside (far root),
// near-tangent, huge and tiny radii, centres far from the origin, origins on the surface. Prints
// the median / max relative t error per family (docs/accelerators.md quotes them) and asserts
// bounds. A naive float solver (centre rounded to float, b^2 - 4ac, (-b +- sqrt) / 2a) runs on the
// same rays to show that the bounds do catch a poor kernel. Then the plane kernel and the hit
// records of spheres and planes through an accelerator.
//
// Reproduce the figures: ctest --test-dir build -R SphereKernel -V (or run build/tests/test_sphere_intersect)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "accel/accelerator.h"
#include "accel/factory/create_accelerator.h"
#include "accel/common/planes.h"
#include "accel/common/sphere.h"
#include "tests/support/test_accel_util.h"

namespace whitted {
namespace {

using namespace whitted::test;
using LD = long double;

struct LdVec {
    LD x, y, z;
};
LD ld_dot(const LdVec& a, const LdVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// The reference: both roots in long double from the exact float ray and double sphere, plus
/// the relative margin (r^2 - p^2) / r^2 of the line's distance p from the centre (< 0: miss).
struct Reference {
    bool hit = false;
    LD t0 = 0, t1 = 0, margin = 0;
};

Reference reference_roots(const Vec3f& o, const Vec3f& d, const Vec3d& c, double radius) {
    const LdVec f{LD(o.x) - LD(c.x), LD(o.y) - LD(c.y), LD(o.z) - LD(c.z)};
    const LdVec dd{LD(d.x), LD(d.y), LD(d.z)};
    const LD r = radius, a = ld_dot(dd, dd), b = ld_dot(f, dd);
    const LdVec p{f.x - dd.x * b / a, f.y - dd.y * b / a, f.z - dd.z * b / a};
    Reference ref;
    ref.margin = (r * r - ld_dot(p, p)) / (r * r);
    const LD disc = a * (r * r - ld_dot(p, p));
    if (disc < 0) return ref;
    const LD q = -b - std::copysign(std::sqrt(disc), b);
    ref.hit = true;
    if (q == 0) return ref;
    ref.t0 = (ld_dot(f, f) - r * r) / q;
    ref.t1 = q / a;
    if (ref.t0 > ref.t1) std::swap(ref.t0, ref.t1);
    return ref;
}

/// What a careless float implementation does: centre rounded to float, the textbook formula.
bool naive_roots(const Vec3f& o, const Vec3f& d, const Vec3d& c, double radius, float& t0, float& t1) {
    const Vec3f f = o - Vec3f(c);
    const float r = float(radius), a = dot(d, d), b = 2.f * dot(f, d), cc = dot(f, f) - r * r;
    const float disc = b * b - 4.f * a * cc;
    if (disc < 0.f) return false;
    t0 = (-b - std::sqrt(disc)) / (2.f * a);
    t1 = (-b + std::sqrt(disc)) / (2.f * a);
    return true;
}

struct Case {
    Vec3f org, dir;
    Vec3d center;
    double radius;
};

/// Error of one root: |t - t_ref| relative to max(|t_ref|, r / |d|) (the second term keeps roots
/// near the origin, e.g. for origins on the surface, from dividing by ~0).
double root_error(double t, LD t_ref, const Case& c) {
    const LD scale = std::max(std::fabs(t_ref), LD(c.radius) / std::sqrt(LD(dot(c.dir, c.dir))));
    return double(std::fabs(LD(t) - t_ref) / scale);
}

struct Stats {
    std::vector<double> err;
    size_t hit_mismatch = 0;  ///< hit/miss differs from the reference with a clear margin
    double median() const {
        if (err.empty()) return 0.0;
        std::vector<double> e = err;
        std::nth_element(e.begin(), e.begin() + long(e.size() / 2), e.end());
        return e[e.size() / 2];
    }
    double max() const { return err.empty() ? 0.0 : *std::max_element(err.begin(), err.end()); }
};

struct FamilyResult {
    Stats f, d, naive, f32c;  ///< float, double, naive float, our kernel with the centre rounded to float
    size_t rays = 0, compared = 0;
};

/// Runs float, double and the naive solver on every case; errors are compared on both roots for
/// rays the reference hits with a relative margin above `min_margin`; hit/miss decisions must
/// agree when |margin| > 1e-3.
FamilyResult run_family(const std::vector<Case>& cases, LD min_margin = 1e-3L) {
    FamilyResult out;
    for (const Case& c : cases) {
        const Reference ref = reference_roots(c.org, c.dir, c.center, c.radius);
        float f0 = 0, f1 = 0, n0 = 0, n1 = 0, c0 = 0, c1 = 0;
        double d0 = 0, d1 = 0;
        const bool fh = sphere_roots(c.org, c.dir, c.center, c.radius, f0, f1);
        // The same kernel with the centre stored in float (f = o - c formed in float).
        const bool ch = sphere_roots(c.org - Vec3f(c.center), c.dir, Vec3d(0.0), c.radius, c0, c1);
        const bool dh = sphere_roots(Vec3d(c.org), Vec3d(c.dir), c.center, c.radius, d0, d1);
        const bool nh = naive_roots(c.org, c.dir, c.center, c.radius, n0, n1);
        ++out.rays;
        const bool clear = std::fabs(ref.margin) > 1e-3L;
        out.f.hit_mismatch += clear && fh != ref.hit;
        out.d.hit_mismatch += clear && dh != ref.hit;
        out.naive.hit_mismatch += clear && nh != ref.hit;
        out.f32c.hit_mismatch += clear && ch != ref.hit;
        if (!ref.hit || ref.margin < min_margin) continue;
        ++out.compared;
        if (fh) {
            out.f.err.push_back(root_error(f0, ref.t0, c));
            out.f.err.push_back(root_error(f1, ref.t1, c));
        }
        if (dh) {
            out.d.err.push_back(root_error(d0, ref.t0, c));
            out.d.err.push_back(root_error(d1, ref.t1, c));
        }
        if (nh) {
            out.naive.err.push_back(root_error(n0, ref.t0, c));
            out.naive.err.push_back(root_error(n1, ref.t1, c));
        }
        if (ch) {
            out.f32c.err.push_back(root_error(c0, ref.t0, c));
            out.f32c.err.push_back(root_error(c1, ref.t1, c));
        }
    }
    return out;
}

void print(const char* family, const FamilyResult& r) {
    std::printf("[ sphere ] %-26s %5zu rays %5zu cmp | float med %.1e max %.1e miss %zu | double med %.1e max %.1e "
                "miss %zu | centre-in-float med %.1e max %.1e miss %zu | naive med %.1e max %.1e miss %zu\n",
                family, r.rays, r.compared, r.f.median(), r.f.max(), r.f.hit_mismatch, r.d.median(), r.d.max(),
                r.d.hit_mismatch, r.f32c.median(), r.f32c.max(), r.f32c.hit_mismatch, r.naive.median(), r.naive.max(),
                r.naive.hit_mismatch);
}

// ---- ray families ----

class Gen {
public:
    explicit Gen(uint32_t seed) : m_rng(seed) {}
    double u01() { return m_u(m_rng); }
    double uniform(double lo, double hi) { return lo + (hi - lo) * u01(); }
    Vec3d unit() {
        const double z = uniform(-1, 1), ph = uniform(0, 2 * 3.14159265358979323846), s = std::sqrt(1 - z * z);
        return {s * std::cos(ph), s * std::sin(ph), z};
    }
    Vec3d in_ball(double r) { return unit() * (r * std::cbrt(u01())); }
    /// A direction length between 0.1 and 10 (t is in units of |dir|).
    double dir_scale() { return std::pow(10.0, uniform(-1, 1)); }

private:
    std::mt19937_64 m_rng;
    std::uniform_real_distribution<double> m_u{0.0, 1.0};
};

/// Origins at `dist_lo..dist_hi` radii from the centre aimed at points within `aim` radii of it.
std::vector<Case> from_outside(Gen& g, int n, Vec3d center_base, double center_spread, double radius, double dist_lo,
                               double dist_hi, double aim = 0.9) {
    std::vector<Case> cases;
    for (int i = 0; i < n; ++i) {
        const Vec3d c = center_base + g.in_ball(center_spread);
        // The origin rounded to float first, so that the ray aims from where it really starts.
        const Vec3d o(Vec3f(c + g.unit() * (radius * g.uniform(dist_lo, dist_hi))));
        const Vec3d target = c + g.in_ball(radius * aim);
        cases.push_back({Vec3f(o), Vec3f(normalize(target - o) * g.dir_scale()), c, radius});
    }
    return cases;
}

std::vector<Case> from_inside(Gen& g, int n, Vec3d center_base, double radius) {
    std::vector<Case> cases;
    for (int i = 0; i < n; ++i) {
        const Vec3d c = center_base + g.in_ball(10.0);
        const Vec3d o = c + g.in_ball(radius * 0.99);
        cases.push_back({Vec3f(o), Vec3f(g.unit() * g.dir_scale()), c, radius});
    }
    return cases;
}

/// Lines at distance radius * (1 - delta) from the centre (delta < 0: just missing).
std::vector<Case> near_tangent(Gen& g, int n, double delta) {
    std::vector<Case> cases;
    for (int i = 0; i < n; ++i) {
        const Vec3d c = g.in_ball(10.0);
        const double r = 1.0;
        const Vec3d dir = g.unit();
        Vec3d side = normalize(cross(dir, g.unit()));
        const Vec3d closest = c + side * (r * (1.0 - delta));
        const Vec3d o = closest - dir * (r * g.uniform(2, 20));
        cases.push_back({Vec3f(o), Vec3f(dir * g.dir_scale()), c, r});
    }
    return cases;
}

/// Origins on the surface (rounded to float), directions into the sphere (far root ~ a chord)
/// and out of it (both roots ~0 and behind).
std::vector<Case> on_surface(Gen& g, int n, double radius) {
    std::vector<Case> cases;
    for (int i = 0; i < n; ++i) {
        const Vec3d c = g.in_ball(10.0);
        const Vec3d nrm = g.unit();
        Vec3d dir = g.unit();
        if ((dot(dir, nrm) > 0) == (i % 2 == 0)) dir = -dir;  // even: inwards
        cases.push_back({Vec3f(c + nrm * radius), Vec3f(dir * g.dir_scale()), c, radius});
    }
    return cases;
}

struct Families {
    std::vector<std::pair<std::string, FamilyResult>> results;
    const FamilyResult& get(const std::string& name) const {
        for (const auto& [n, r] : results)
            if (n == name) return r;
        throw std::runtime_error("no family " + name);
    }
};

const Families& families() {
    static const Families all = [] {
        Families fam;
        Gen g(2024);
        constexpr int n = 4000;
        auto add = [&](const char* name, const std::vector<Case>& cases, LD min_margin = 1e-3L) {
            fam.results.push_back({name, run_family(cases, min_margin)});
            print(name, fam.results.back().second);
        };
        add("outside r=1", from_outside(g, n, {0, 0, 0}, 10.0, 1.0, 1.5, 50.0));
        add("inside r=1 (far root)", from_inside(g, n, {0, 0, 0}, 1.0));
        add("near-tangent 1-1e-2", near_tangent(g, n, 1e-2));
        add("near-tangent 1-1e-4", near_tangent(g, n, 1e-4), 0);
        add("near-tangent 1-1e-6", near_tangent(g, n, 1e-6), 0);
        add("tangent (1 - 0)", near_tangent(g, n, 0.0), 0);
        add("huge r=1e6 outside", from_outside(g, n, {0, 0, 0}, 10.0, 1e6, 1.5, 5.0));
        add("huge r=1e6 inside (sky)", from_inside(g, n, {0, 0, 0}, 1e6));
        add("tiny r=1e-4", from_outside(g, n, {0, 0, 0}, 1.0, 1e-4, 2.0, 1e4));
        add("far c~1e5 r=1, org near", from_outside(g, n, {1e5, -7e4, 3e4}, 10.0, 1.0, 1.5, 50.0));
        add("far c~1e5 r=1e-4, org near", from_outside(g, n, {1e5, -7e4, 3e4}, 10.0, 1e-4, 2.0, 1e3));
        add("far c~1e5 r=1, org at 0", [&] {
            std::vector<Case> cases;
            for (int i = 0; i < n; ++i) {
                const Vec3d c = Vec3d(1e5, -7e4, 3e4) + g.in_ball(1e3);
                const Vec3d o(Vec3f(g.in_ball(1.0))), target = c + g.in_ball(0.9);
                cases.push_back({Vec3f(o), Vec3f(normalize(target - o) * g.dir_scale()), c, 1.0});
            }
            return cases;
        }());
        add("origin on surface r=1", on_surface(g, n, 1.0));
        return fam;
    }();
    return all;
}

// Bounds: the float kernel's t is within a few ulps (6e-8 each) of the exact root wherever the
// root is well conditioned; near tangency the error grows like eps / margin (the root moves by
// dp * p / sqrt(r^2 - p^2)), so those families get bounds scaled by their margin.
struct Bound {
    const char* family;
    double float_median, float_max, double_max;
};
constexpr Bound kBounds[] = {
    {"outside r=1", 1e-7, 1e-6, 1e-14},
    {"inside r=1 (far root)", 1e-7, 1e-6, 1e-14},
    {"near-tangent 1-1e-2", 2e-7, 3e-6, 1e-14},
    {"near-tangent 1-1e-4", 2e-6, 3e-5, 1e-13},
    {"huge r=1e6 outside", 1e-7, 1e-6, 1e-14},
    {"huge r=1e6 inside (sky)", 1e-7, 1e-6, 1e-14},
    {"tiny r=1e-4", 1e-7, 1e-6, 1e-14},
    {"far c~1e5 r=1, org near", 1e-7, 1e-6, 1e-14},
    {"far c~1e5 r=1e-4, org near", 1e-7, 1e-6, 1e-14},
    {"far c~1e5 r=1, org at 0", 1e-7, 1e-6, 1e-14},
    {"origin on surface r=1", 1e-7, 1e-5, 1e-14},
};

TEST(SphereKernel, RelativeErrorAgainstLongDouble) {
    for (const Bound& b : kBounds) {
        SCOPED_TRACE(b.family);
        const FamilyResult& r = families().get(b.family);
        ASSERT_GT(r.compared, 100u);
        EXPECT_LE(r.f.median(), b.float_median);
        EXPECT_LE(r.f.max(), b.float_max);
        EXPECT_LE(r.d.max(), b.double_max);
        EXPECT_EQ(r.f.hit_mismatch, 0u);
        EXPECT_EQ(r.d.hit_mismatch, 0u);
        // Every hit the reference sees with a margin is also a hit in float and double.
        EXPECT_GE(r.f.err.size(), 2 * r.compared);
        EXPECT_GE(r.d.err.size(), 2 * r.compared);
    }
}

/// The bounds above reject poorer kernels on the same rays: the textbook float solver fails them
/// in most families, and our kernel with the centre stored in float fails the far-away ones.
TEST(SphereKernel, BoundsRejectPoorerKernels) {
    int naive_fails = 0;
    for (const Bound& b : kBounds) {
        const FamilyResult& r = families().get(b.family);
        naive_fails += r.naive.hit_mismatch > 0 || r.naive.max() > b.float_max || r.naive.median() > b.float_median;
    }
    EXPECT_GE(naive_fails, 8);
    for (const char* far : {"far c~1e5 r=1, org near", "far c~1e5 r=1e-4, org near"}) {
        const FamilyResult& r = families().get(far);
        EXPECT_TRUE(r.f32c.hit_mismatch > 0 || r.f32c.max() > 1e-6) << far;
    }
}

TEST(SphereKernel, InsideGivesFarRootAndTangentIsOneRoot) {
    float t0, t1;
    // From the centre of a unit sphere along +x with |dir| = 2: roots -0.5 and 0.5.
    ASSERT_TRUE(sphere_roots(Vec3f(3, 4, 5), Vec3f(2, 0, 0), Vec3d(3, 4, 5), 1.0, t0, t1));
    EXPECT_FLOAT_EQ(t0, -0.5f);
    EXPECT_FLOAT_EQ(t1, 0.5f);
    // Exactly tangent (the line y = 1 touches the unit sphere at x = 0): one double root at t = 5.
    ASSERT_TRUE(sphere_roots(Vec3f(-5, 1, 0), Vec3f(1, 0, 0), Vec3d(0, 0, 0), 1.0, t0, t1));
    EXPECT_FLOAT_EQ(t0, 5.f);
    EXPECT_FLOAT_EQ(t1, 5.f);
    // Just missing, and degenerate input.
    EXPECT_FALSE(sphere_roots(Vec3f(-5, 1.0001f, 0), Vec3f(1, 0, 0), Vec3d(0, 0, 0), 1.0, t0, t1));
    EXPECT_FALSE(sphere_roots(Vec3f(-5, 0, 0), Vec3f(0, 0, 0), Vec3d(0, 0, 0), 1.0, t0, t1));
    // Origin exactly at the tangent point, moving along the tangent: double root at 0.
    ASSERT_TRUE(sphere_roots(Vec3f(0, 1, 0), Vec3f(1, 0, 0), Vec3d(0, 0, 0), 1.0, t0, t1));
    EXPECT_EQ(t0, 0.f);
    EXPECT_EQ(t1, 0.f);
}

// ---- planes ----

TEST(AccelPlaneKernel, ParallelBackSideAndTmax) {
    const Vec3d point(0, 2, 0), normal(0, 1, 0);
    float t = -1.f;
    Ray r;
    r.org = {1, 0, 1};
    // Parallel, with +0 and -0 in the normal's component, from off the plane and from inside it.
    for (float zero : {0.f, -0.f})
        for (float y : {0.f, 2.f}) {
            r.org.y = y;
            r.dir = {1, zero, 0.5f};
            EXPECT_FALSE(intersect_plane(r, point, normal, t)) << zero << " " << y;
            EXPECT_EQ(t, -1.f);  // untouched: no NaN written
        }
    // Front and back side.
    r.org = {1, 0, 1};
    r.dir = {0, 4, 0};
    ASSERT_TRUE(intersect_plane(r, point, normal, t));
    EXPECT_EQ(t, 0.5f);
    r.org = {1, 5, 1};
    r.dir = {0, -1, 0};
    ASSERT_TRUE(intersect_plane(r, point, normal, t));
    EXPECT_EQ(t, 3.f);
    // tfar exactly at the hit finds it; one ulp less does not; tnear at the hit does not.
    r.tfar = 3.f;
    EXPECT_TRUE(intersect_plane(r, point, normal, t));
    r.tfar = std::nextafter(3.f, 0.f);
    EXPECT_FALSE(intersect_plane(r, point, normal, t));
    r.tfar = kInfinity;
    r.tnear = 3.f;
    EXPECT_FALSE(intersect_plane(r, point, normal, t));
    // Away from the plane: no hit behind the origin; a nearly parallel ray far out stays finite.
    r.tnear = 0.f;
    r.dir = {0, 1, 0};
    EXPECT_FALSE(intersect_plane(r, point, normal, t));
    r.dir = {1, -1e-40f, 0};  // t = 3e40 overflows float: no hit at infinity
    EXPECT_FALSE(intersect_plane(r, point, normal, t)) << t;
}

/// Filter for the hit-record tests: geometry 2 (a plane) is transparent, the rest opaque.
class GlassGeom2 final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit& h) const override { return h.geom == 2 ? Color(0.5f) : Color(0.f); }
    uint32_t mesh_flags(uint32_t g) const override { return g == 2 ? kNeedsTransmittance : 0; }
};

TEST(AccelPlaneKernel, HitRecordsThroughEveryBackend) {
    Scene s;
    s.spheres.push_back({Vec3d(0, 0, 5), 1.0, 0, "ball"});      // geom 0
    s.planes.push_back({Vec3d(0, -1, 0), Vec3d(0, 1, 0), Vec3d(1, 0, 0), 0, "floor"});  // geom 1
    s.planes.push_back({Vec3d(0, 0, 3), Vec3d(0, 0, -1), Vec3d(1, 0, 0), 0, "glass"});  // geom 2
    GlassGeom2 filter;
    for (const std::string& name : accelerator_names()) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, s, filter);
        Ray r;
        r.dir = {0, 0, 1};
        // Through the glass plane (t = 3) to the sphere (t = 4): the plane is nearer.
        Hit h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 2u);
        EXPECT_EQ(h.inst, kInvalidId);
        EXPECT_EQ(h.prim, 0u);
        EXPECT_EQ(h.t, 3.f);
        // From inside the sphere (the glass plane now behind the origin): the far root.
        r.org = {0, 0, 5.5f};
        h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 0u);
        EXPECT_EQ(h.inst, kInvalidId);
        EXPECT_EQ(h.prim, 0u);
        EXPECT_EQ(h.u, 0.f);
        EXPECT_EQ(h.v, 0.f);
        EXPECT_FLOAT_EQ(h.t, 0.5f);
        // Down to the floor, from above and (back side) from below.
        r.org = {3, 0, 0};
        r.dir = {0, -2, 0};
        h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 1u);
        EXPECT_EQ(h.t, 0.5f);
        r.org = {3, -3, 0};
        r.dir = {0, 1, 0};
        EXPECT_EQ(accel->intersect(r, RayKind::Camera).t, 2.f);
        // Parallel to the floor, in it: nothing.
        r.org = {3, -1, 0};
        r.dir = {1, -0.f, 0};
        EXPECT_FALSE(accel->intersect(r, RayKind::Camera).valid());
        // Shadow: through the glass plane only (x 0.5), then into the opaque sphere (0).
        r.org = {0, 0, 0};
        r.dir = {0, 0, 1};
        r.tfar = 3.5f;
        EXPECT_FLOAT_EQ(accel->transmittance(r).x, 0.5f);
        r.tfar = 4.5f;
        EXPECT_EQ(accel->transmittance(r).x, 0.f);
        r.tfar = 3.f;  // tfar exactly at the plane: crossed
        EXPECT_FLOAT_EQ(accel->transmittance(r).x, 0.5f);
    }
}

}  // namespace
}  // namespace whitted
