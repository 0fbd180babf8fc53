// The ray/quadric kernel (accel/common/quadric.h) and the quadric's surface points (scene.h):
// hits at known distances for each kind, open and capped, rays along the axis and parallel to a
// cone's side, rims that no ray slips through, far from the origin, under a non-uniform scale.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "accel/common/quadric.h"
#include "accel/factory/create_accelerator.h"
#include "scene/scene.h"

namespace whitted {
namespace {

using K = QuadricKind;

uint8_t g_face[2];  ///< the faces of the last crossings() call
int crossings(const Quadric& q, Vec3d o, Vec3d d, double t[2]) { return quadric_crossings(QuadricShape(q), o, d, t, g_face); }

TEST(Quadric, CylinderSideAndCaps) {
    // Unit cylinder along +Y from y = 0 to 2.
    const Quadric closed = make_quadric(K::Cylinder, {0, 0, 0}, {0, 2, 0}, 1.0, 1.0, true);
    const Quadric open = make_quadric(K::Cylinder, {0, 0, 0}, {0, 2, 0}, 1.0, 1.0, false);
    double t[2];
    // Across the side at y = 1, from x = -5.
    ASSERT_EQ(crossings(closed, {-5, 1, 0}, {1, 0, 0}, t), 2);
    EXPECT_NEAR(t[0], 4.0, 1e-12);
    EXPECT_NEAR(t[1], 6.0, 1e-12);
    ASSERT_EQ(crossings(open, {-5, 1, 0}, {2, 0, 0}, t), 2);  // t in units of the (unnormalised) direction
    EXPECT_NEAR(t[0], 2.0, 1e-12);
    EXPECT_NEAR(t[1], 3.0, 1e-12);
    // Along the axis: the caps of the closed one, nothing for the open one.
    ASSERT_EQ(crossings(closed, {0.3, -4, 0.2}, {0, 1, 0}, t), 2);
    EXPECT_NEAR(t[0], 4.0, 1e-12);
    EXPECT_NEAR(t[1], 6.0, 1e-12);
    EXPECT_EQ(g_face[0], 1);  // in through the base cap, out through the top cap
    EXPECT_EQ(g_face[1], 2);
    EXPECT_EQ(crossings(open, {0.3, -4, 0.2}, {0, 1, 0}, t), 0);
    // Past the end: misses; beside it: misses.
    EXPECT_EQ(crossings(closed, {-5, 2.5, 0}, {1, 0, 0}, t), 0);
    EXPECT_EQ(crossings(closed, {-5, 1, 1.01}, {1, 0, 0}, t), 0);
    // Diagonal in through the base cap at (0.75, 0, 0), out through the side at (1, 1, 0).
    ASSERT_EQ(crossings(closed, {0.5, -1, 0}, {0.25, 1, 0}, t), 2);
    EXPECT_NEAR(t[0], 1.0, 1e-12);
    EXPECT_NEAR(t[1], 2.0, 1e-12);
    EXPECT_EQ(g_face[0], 1);
    EXPECT_EQ(g_face[1], 0);
    // Downwards: in through the top cap.
    ASSERT_EQ(crossings(closed, {0.5, 5, 0}, {0, -1, 0}, t), 2);
    EXPECT_EQ(g_face[0], 2);
    EXPECT_EQ(g_face[1], 1);
}

TEST(Quadric, ConeSlopeApexAndParallelRays) {
    // Cone along +Z, radius 1 at z = 0 to a point at z = 1.
    const Quadric cone = make_quadric(K::Cone, {0, 0, 0}, {0, 0, 1}, 1.0, 0.0, false);
    double t[2];
    // Horizontal at z = 0.5 (radius 0.5): x = -0.5 and 0.5.
    ASSERT_EQ(crossings(cone, {-3, 0, 0.5}, {1, 0, 0}, t), 2);
    EXPECT_NEAR(t[0], 2.5, 1e-12);
    EXPECT_NEAR(t[1], 3.5, 1e-12);
    // Parallel to a side line (a = 0): one crossing, the other nappe is beyond the apex.
    ASSERT_EQ(crossings(cone, {-0.5, 0, -0.5}, {1, 0, 1}, t), 1);
    const double z = -0.5 + t[0];
    EXPECT_NEAR(std::hypot(-0.5 + t[0], 0.0), 1.0 - z, 1e-12);
    // Through the apex along the axis from above: the apex (a tangent point) only when open...
    EXPECT_LE(crossings(cone, {0, 0, 3}, {0, 0, -1}, t), 2);
    // ...and the base disc when capped.
    const Quadric capped = make_quadric(K::Cone, {0, 0, 0}, {0, 0, 1}, 1.0, 0.0, true);
    ASSERT_EQ(crossings(capped, {0.2, 0.1, 3}, {0, 0, -1}, t), 2);
    EXPECT_NEAR(t[1], 3.0, 1e-12);  // leaves through the base at z = 0
    EXPECT_NEAR(3.0 - t[0], 1.0 - std::hypot(0.2, 0.1), 1e-12);
    // The other nappe (z > 1) is not part of the cone.
    EXPECT_EQ(crossings(cone, {-3, 0, 1.5}, {1, 0, 0}, t), 0);
    EXPECT_EQ(crossings(capped, {-3, 0, 1.5}, {1, 0, 0}, t), 0);
}

TEST(Quadric, DiscAndAnnulus) {
    const Quadric disc = make_quadric(K::Disc, {1, 2, 3}, {1, 3, 3}, 2.0, 2.0, false);
    Quadric ring = disc;
    ring.inner_radius = 1.0;
    double t[2];
    ASSERT_EQ(crossings(disc, {1.5, 5, 3}, {0, -1, 0}, t), 1);
    EXPECT_NEAR(t[0], 3.0, 1e-12);
    EXPECT_EQ(crossings(ring, {1.5, 5, 3}, {0, -1, 0}, t), 0);  // in the hole
    ASSERT_EQ(crossings(ring, {2.5, 5, 3}, {0, -1, 0}, t), 1);
    EXPECT_EQ(crossings(disc, {3.5, 5, 3}, {0, -1, 0}, t), 0);  // outside
    EXPECT_EQ(crossings(disc, {0, 2, 3}, {1, 0, 0}, t), 0);     // in its plane
    // Behind the origin (t = -3, -1e-4): left out, from either side of the plane; from a point in
    // the plane the crossing at t = 0 is kept, as is one just in front of the origin.
    EXPECT_EQ(crossings(disc, {1.5, 5, 3}, {0, 1, 0}, t), 0);
    EXPECT_EQ(crossings(disc, {1.5, -1, 3}, {0, -1, 0}, t), 0);
    EXPECT_EQ(crossings(disc, {1.5, 2.0001, 3}, {0, 1, 0}, t), 0);
    ASSERT_EQ(crossings(disc, {1.5, 2, 3}, {0.6, 0.8, 0}, t), 1);
    EXPECT_EQ(t[0], 0.0);
    ASSERT_EQ(crossings(disc, {1.5, 2.0001, 3}, {0, -1, 0}, t), 1);
    EXPECT_NEAR(t[0], 1e-4, 1e-15);
    const QuadricPoint p = quadric_point(disc, {2, 2.0000001, 3});
    EXPECT_NEAR(p.p.y, 2.0, 1e-15);
    EXPECT_NEAR(p.n.y, 1.0, 1e-15);
}

/// No ray through a capped solid's rim slips through: every line that passes between the side and
/// a cap, at every angle, crosses the solid twice (Quadric is watertight by construction).
TEST(Quadric, RimsAreWatertight) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Quadric shapes[] = {make_quadric(K::Cylinder, {0.1, -0.3, 0.2}, {0.4, 1.7, -0.5}, 0.6, 0.6, true),
                              make_quadric(K::Cone, {0, 0, 0}, {0, 0, 1.3}, 0.9, 0.35, true)};
    for (const Quadric& q : shapes) {
        int misses = 0, odd = 0;
        for (int i = 0; i < 20000; ++i) {
            // A point on a rim (object space), a direction pointing into the solid's half-space
            // so that the line enters it there.
            const double phi = 2.0 * kPiD * u(rng);
            const bool top = i & 1;
            const double r = top ? q.radius1 : q.radius0, z = top ? q.height : 0.0;
            const Vec3d rim = q.world_from_object.apply_point({r * std::cos(phi), r * std::sin(phi), z});
            const Vec3d inside = q.world_from_object.apply_point({0.3 * r * std::cos(phi + 1.0), 0.0, 0.5 * q.height});
            const Vec3d d = normalize(inside - rim);
            double t[2];
            const int n = crossings(q, rim - d * 10.0, d, t);
            misses += n == 0;
            odd += n == 1;
            if (n == 2) {
                EXPECT_NEAR(t[0], 10.0, 1e-9);
                // The face named is the one crossed: the ray enters against its outward normal.
                const QuadricPoint p = quadric_point(q, rim - d * 10.0 + d * t[0], g_face[0]);
                EXPECT_LT(dot(p.n, d), 1e-9) << "face " << int(g_face[0]);
            }
        }
        EXPECT_EQ(misses, 0);
        EXPECT_EQ(odd, 0);
    }
}

/// A cylinder far from the origin, hit from far away: t keeps double precision relative to the
/// distance travelled (the origin is moved next to the quadric before solving).
TEST(Quadric, FarFromTheOriginAndFarRays) {
    const Vec3d c{1e6, -2e6, 3e5};
    const Quadric q = make_quadric(K::Cylinder, c, c + Vec3d{0, 0, 1e-3}, 1e-3, 1e-3, true);
    double t[2];
    ASSERT_EQ(crossings(q, c + Vec3d{-1e4, 0, 5e-4}, {1, 0, 0}, t), 2);
    EXPECT_NEAR(t[0], 1e4 - 1e-3, 1e-9);
    EXPECT_NEAR(t[1], 1e4 + 1e-3, 1e-9);
    // Grazing the side tangentially: a double root or a miss, never a crossing off the surface.
    const int n = crossings(q, c + Vec3d{-1e4, 1e-3, 5e-4}, {1, 0, 0}, t);
    if (n == 2) {
        EXPECT_NEAR(t[0], 1e4, 1e-5);
    }
}

TEST(Quadric, NonUniformScaleAndNormals) {
    // A unit cylinder scaled by 2 along X: an elliptic cylinder with semi-axes 2 and 1.
    const Quadric q = make_quadric(K::Cylinder, {0, 0, 0}, {0, 0, 1}, 1.0, 1.0, true, Mat4d::scale({2, 1, 1}));
    double t[2];
    ASSERT_EQ(crossings(q, {-5, 0, 0.5}, {1, 0, 0}, t), 2);
    EXPECT_NEAR(t[0], 3.0, 1e-12);
    ASSERT_EQ(crossings(q, {0, -5, 0.5}, {0, 1, 0}, t), 2);
    EXPECT_NEAR(t[0], 4.0, 1e-12);
    // Normal of the ellipse x^2/4 + y^2 = 1 at (sqrt 2, sqrt(1/2)): along (x/4, y).
    const QuadricPoint p = quadric_point(q, {std::sqrt(2.0), std::sqrt(0.5), 0.5});
    const Vec3d expect = normalize(Vec3d{std::sqrt(2.0) / 4.0, std::sqrt(0.5), 0.0});
    EXPECT_NEAR(dot(p.n, expect), 1.0, 1e-12);
    EXPECT_EQ(p.part, 0);
    // Caps face outwards, the part is named.
    const QuadricPoint top = quadric_point(q, {0.2, 0.1, 1.0000001});
    EXPECT_EQ(top.part, 2);
    EXPECT_NEAR(top.n.z, 1.0, 1e-15);
    const QuadricPoint base = quadric_point(q, {0.2, 0.1, -1e-9});
    EXPECT_EQ(base.part, 1);
    EXPECT_NEAR(base.n.z, -1.0, 1e-15);
    // Bounds: exact for the ellipse.
    const Bounds3d b = quadric_bounds(q);
    EXPECT_NEAR(b.lo.x, -2.0, 1e-12);
    EXPECT_NEAR(b.hi.y, 1.0, 1e-12);
    EXPECT_NEAR(b.hi.z, 1.0, 1e-12);
}

TEST(Quadric, ConeNormalsAndUvs) {
    // Radius 1 at z = 0 to 0 at z = 1: the side's outward normal is (1, 0, 1)/sqrt 2 at +X.
    const Quadric q = make_quadric(K::Cone, {0, 0, 0}, {0, 0, 1}, 1.0, 0.0, false);
    // The axis is +Z already: the frame is the identity.
    const QuadricPoint p = quadric_point(q, {0.5, 0, 0.5});
    EXPECT_NEAR(dot(p.n, normalize(Vec3d{1, 0, 1})), 1.0, 1e-12);
    EXPECT_NEAR(p.v, 0.5, 1e-12);
    EXPECT_NEAR(p.u, 0.5, 1e-12);  // atan2(0, +x) = 0 -> 0.5
}

/// Every backend reports the face a ray crossed as Hit::prim (SceneView shades that face: at a rim
/// the nearest face by distance can be the other one, whose normal may face away from the ray).
TEST(Quadric, EveryBackendNamesTheFaceCrossed) {
    Scene s;
    s.materials.resize(1);
    s.quadrics.push_back(make_quadric(K::Cylinder, {0, 0, 0}, {0, 2, 0}, 1.0, 1.0, true));
    struct Opaque final : SurfaceFilter {
        bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
        Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }
        uint32_t mesh_flags(uint32_t) const override { return 0; }
    } filter;
    Ray up, down, side;
    up.org = {0.2f, -3.f, 0.1f}, up.dir = {0.f, 1.f, 0.f};
    down.org = {0.2f, 5.f, 0.1f}, down.dir = {0.f, -1.f, 0.f};
    side.org = {-4.f, 1.f, 0.f}, side.dir = {1.f, 0.f, 0.f};
    for (const char* name : {"embree", "bvh", "bvh:width=2", "bvh:precision=double", "kdop", "grid", "octree", "brute"}) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, s, filter);
        EXPECT_EQ(accel->intersect(up, RayKind::Camera).prim, 1u);
        EXPECT_EQ(accel->intersect(down, RayKind::Camera).prim, 2u);
        EXPECT_EQ(accel->intersect(side, RayKind::Camera).prim, 0u);
    }
}

TEST(Quadric, DegenerateInputGivesNoCrossing) {
    const Quadric q = make_quadric(K::Cylinder, {0, 0, 0}, {0, 1, 0}, 1.0, 1.0, true);
    double t[2];
    EXPECT_EQ(crossings(q, {0, 0.5, -3}, {0, 0, 0}, t), 0);
    EXPECT_EQ(crossings(q, {0, 0.5, -3}, {0, NAN, 1}, t), 0);
    EXPECT_EQ(crossings(q, {INFINITY, 0.5, -3}, {0, 0, 1}, t), 0);
}

// The world-space axis bound (QuadricShape::line_misses) only drops lines the full test misses:
// lines aimed at points within 1.5 reach of the axis, most of them just outside the shape,
// for cylinders and cones under rigid, scaled and sheared transforms and far from the origin.
TEST(Quadric, AxisBoundRejectsOnlyMisses) {
    Mat4d shear = Mat4d::identity();
    shear(0, 1) = 0.7;
    shear(2, 0) = -0.4;
    Mat4d scale = Mat4d::identity();
    scale(0, 0) = 3.0;
    scale(2, 2) = 0.25;
    Mat4d far = Mat4d::identity();
    far(0, 3) = 1e5;
    far(1, 3) = -3e4;
    const std::vector<Quadric> shapes{
        make_quadric(K::Cylinder, {0, 0, 0}, {0.3, 2, 0.1}, 0.5, 0.5, true),
        make_quadric(K::Cylinder, {1, 0, 0}, {1, 0, 3}, 0.2, 0.2, false, shear),
        make_quadric(K::Cone, {0, 0, 0}, {0, 0, 1}, 0.8, 0.1, true, scale),
        make_quadric(K::Cone, {0, 0, 0}, {1, 1, 1}, 0.0, 0.4, false, far * shear),
    };
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const Quadric& q : shapes) {
        const QuadricShape bounded(q);
        QuadricShape full = bounded;
        full.reach = std::numeric_limits<double>::infinity();  // no bound: the full test alone
        ASSERT_TRUE(std::isfinite(bounded.reach));
        int rejected = 0, hits = 0;
        for (int i = 0; i < 20000; ++i) {
            // A point near the shape's axis segment, a random direction through it.
            const double z = 0.5 + 0.7 * u(rng);
            const Vec3d on_axis = q.world_from_object.apply_point({0, 0, z * q.height});
            const Vec3d target = on_axis + Vec3d{u(rng), u(rng), u(rng)} * (1.5 * bounded.reach);
            const Vec3d d = normalize(Vec3d{u(rng), u(rng), u(rng)});
            const Vec3d o = target - d * (10.0 + 5.0 * u(rng));
            double t_full[2], t_bounded[2];
            uint8_t f_full[2], f_bounded[2];
            const int n_full = quadric_crossings(full, o, d, t_full, f_full);
            const int n_bounded = quadric_crossings(bounded, o, d, t_bounded, f_bounded);
            ASSERT_EQ(n_bounded, n_full) << "ray " << i;
            for (int k = 0; k < n_full; ++k) EXPECT_EQ(t_bounded[k], t_full[k]);
            rejected += bounded.line_misses(o, d);
            hits += n_full > 0;
        }
        EXPECT_GT(rejected, 1000);  // the bound does reject lines
        EXPECT_GT(hits, 1000);      // and the rays do find the shape
    }
}

}  // namespace
}  // namespace whitted
