// Self-intersection at any scale and hit-point error against the double reference
// (docs/numerical-stability.md, sections 1 and 7). Bounded for CI; `whitted bench stability` runs
// the same probes with more points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "benchmarks/stability_probes.h"
#include "core/ray_offset.h"

namespace whitted::stress {
namespace {

const double kScales[] = {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6};
const double kTranslations[] = {0.0, 1e3, 1e5};

/// The object spans at least 16 float steps at its position: below that its world-space float
/// image collapses (a 1e-4 object at 1e3, a 1e-2 object at 1e5) and its facets, normals and
/// neighbours cannot be told apart in float; those cases only have to avoid self-hits.
bool resolvable(double s, double t) { return s >= 16.0 * double(ulp(float(t + s))); }

std::string label(const SelfIntersectionConfig& c) {
    const char* surface = c.surface == ProbeSurface::AnalyticSphere ? "analytic sphere"
                          : c.surface == ProbeSurface::TiltedQuad   ? "tilted quad"
                          : c.smooth_normals                         ? "mesh (smooth normals)"
                                                                     : "mesh (flat)";
    return c.accel + " " + surface + " s=" + std::to_string(c.scale) + " t=" + std::to_string(c.translation);
}

// The offset kernel itself: at least kOffsetUlps ulp(max(max|p|, scale)) along n (rounded away
// from the surface), at most kOffsetUlps + 2 (rounding of each component), the same relative amount
// at every magnitude, never a denormal step (flush-to-zero would cancel it), and the sign of n
// respected component by component. Half the points lie on a primitive up to 2^20 times larger
// than the point (SurfacePoint::offset_scale): the unit is then that of the primitive.
TEST(StressOffset, KernelScalesWithMagnitude) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.f, 1.f), e(-40.f, 40.f), larger(0.f, 20.f);
    for (int i = 0; i < 20000; ++i) {
        const float mag = std::exp2(e(rng));
        const Vec3f p = Vec3f(u(rng), u(rng), u(rng)) * mag;
        const Vec3f n = normalize(Vec3f(u(rng), u(rng), u(rng)));
        if (n == Vec3f(0.f)) continue;
        const float scale = i % 2 == 0 ? 0.f : mag * std::exp2(larger(rng));
        const Vec3f o = offset_ray_origin(p, scale, n);
        const double step =
            std::max(double(ulp(std::max(max_abs(p), scale))), double(std::numeric_limits<float>::min()));
        const double along = dot(Vec3d(o) - Vec3d(p), Vec3d(n)) / step;
        EXPECT_GE(along, 4.0 * (1.0 - 1e-6)) << i;  // float n is unit to ~1e-7
        EXPECT_LE(along, 4.0 + 3.0 * std::sqrt(3.0)) << i;  // one step per component, maybe in the next binade
        for (int k = 0; k < 3; ++k) {
            if (n[k] > 0.f) {
                EXPECT_GT(o[k], p[k]);
            } else if (n[k] < 0.f) {
                EXPECT_LT(o[k], p[k]);
            }
            EXPECT_TRUE(o[k] == 0.f || std::fabs(o[k]) >= std::numeric_limits<float>::min());
        }
    }
    // At the origin: FLT_MIN steps, which survive flush-to-zero.
    const Vec3f o = offset_ray_origin(Vec3f(0.f), 0.f, Vec3f(0, 0, 1));
    EXPECT_GE(o.z, 4.f * std::numeric_limits<float>::min());
    // At the origin on a primitive of size 8: 4 ulp(8) = 4 * 2^-20.
    EXPECT_GE(offset_ray_origin(Vec3f(0.f), 8.f, Vec3f(0, 0, 1)).z, 0x1p-18f);
    EXPECT_EQ(guaranteed_gap(Vec3f(0.f), 8.f), 12.f * 0x1p-20f);
}

// Random points of a closed tessellated sphere and of an analytic sphere, scaled 1e-4 .. 1e6 and
// translated up to 1e5 (rotated, transforms in double); reflection, refraction and shadow rays
// over the hemisphere (half uniform, half grazing down to cos 1e-4) leave each point exactly as
// the integrator spawns them. None may hit its own surface, and neighbour surfaces
// kGuaranteedGapUlps ulp(max|p|) in front (outside and inside) must be hit.
TEST(StressSelfIntersection, NoSelfHitsAndNeighboursHitAtAnyScale) {
    for (const char* accel : {"bvh", "embree"})
        for (int surface = 0; surface < 3; ++surface)
            for (double t : kTranslations)
                for (double s : kScales) {
                    SelfIntersectionConfig c;
                    c.accel = accel;
                    c.surface = surface == 2 ? ProbeSurface::AnalyticSphere : ProbeSurface::MeshSphere;
                    c.smooth_normals = surface == 1;
                    c.scale = s;
                    c.translation = t;
                    c.points = 300;
                    c.directions = 6;
                    c.gap_ulps = kGuaranteedGapUlps;
                    c.seed = uint64_t(7 + surface);
                    const SelfIntersectionResult r = probe_self_intersection(c);
                    const std::string what = label(c);
                    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.self_hits[k], 0u) << what << " kind " << k;
                    if (!resolvable(s, t)) continue;
                    EXPECT_GT(r.points, c.points * 9 / 10) << what;
                    EXPECT_GT(r.min_offset_ulps, 0.0) << what;
                    EXPECT_LE(r.max_offset_ulps, double(kGuaranteedGapUlps)) << what;
                    EXPECT_EQ(r.neighbour_misses[0], 0u) << what << " reflection";
                    EXPECT_EQ(r.neighbour_misses[1], 0u) << what << " refraction";
                    // Smooth normals lift shadow origins onto the smooth surface (Hanika 2021): up
                    // to the tessellation's sag above the facet, beyond a neighbour ulps away.
                    if (!c.smooth_normals) {
                        EXPECT_EQ(r.neighbour_misses[2], 0u) << what << " shadow";
                    }
                }
}

// The same probe with Wächter & Binder's offset as published: neighbours within its 256-ulp (and,
// below |p| = 1/32, 1/65536 absolute) offset are skipped, so the test above can fail.
TEST(StressSelfIntersection, PreviousOffsetSkipsNeighbours) {
    for (double s : {1e-4, 1.0}) {
        SelfIntersectionConfig c;
        c.scale = s;
        c.points = 200;
        c.directions = 4;
        c.gap_ulps = kGuaranteedGapUlps;
        c.offset = wachter_binder_2019;
        const SelfIntersectionResult r = probe_self_intersection(c);
        const uint64_t rays = r.rays[0] + r.rays[1] + r.rays[2];
        const uint64_t misses = r.neighbour_misses[0] + r.neighbour_misses[1] + r.neighbour_misses[2];
        EXPECT_GT(misses, rays / 2) << "s=" << s;
        if (s == 1e-4) {
            EXPECT_GT(r.max_offset_ulps, 1e6);  // 1/65536 is ~2e6 ulps of 1e-4
        }
    }
}

/// The large tilted square through the world origin at `scale`, `points` points x 6 directions.
SelfIntersectionConfig tilted_quad(const char* accel, double scale, int points) {
    SelfIntersectionConfig c;
    c.accel = accel;
    c.surface = ProbeSurface::TiltedQuad;
    c.scale = scale;
    c.points = points;
    c.directions = 6;
    return c;
}

// A large tilted square through the world origin, points down to 1e-4 of its size from the
// origin: SceneView interpolates the hit point from float world-space vertices far larger than the
// point, so its error is thousands of ulp(max|p|) (cancellation) and no offset relative to |p|
// covers it. With the exact hit point (emulated here) the same offset has no self-hits at any
// scale.
TEST(StressSelfIntersection, TiltedQuadThroughOriginWithDoubleHitPoint) {
    for (const char* accel : {"bvh", "embree"})
        for (double s : kScales) {
            SelfIntersectionConfig c = tilted_quad(accel, s, 300);
            c.exact_point = true;
            const SelfIntersectionResult r = probe_self_intersection(c);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(r.self_hits[k], 0u) << label(c) << " kind " << k;
        }
}

// The renderer's own hit point (SceneView computes it in double): the tilted square through the
// origin has no self-hits and a small error.
TEST(StressSelfIntersection, TiltedQuadThroughOriginRendererHitPoint) {
    for (const char* accel : {"bvh", "embree"}) {
        const SelfIntersectionConfig c = tilted_quad(accel, 1.0, 300);
        const SelfIntersectionResult r = probe_self_intersection(c);
        EXPECT_GT(r.rays[0] + r.rays[1] + r.rays[2], 3000u) << accel;
        for (int k = 0; k < 3; ++k) EXPECT_EQ(r.self_hits[k], 0u) << accel << " kind " << k;
        std::vector<double> e = r.point_error_ulps;
        ASSERT_FALSE(e.empty());
        EXPECT_LE(distribution(e).max, 4.0) << accel;
    }
}

// A large triangle with hit points near the world origin, with every backend: the tilted square
// through the origin (points down to 1e-4 of its size from the origin), neighbours at
// kGuaranteedGapUlps offset units. The float watertight triangle test's t error scales with the
// vertices' coordinates, not with the small |p|: with offsets in ulps of max|p| alone, the
// backends without a per-primitive box test (brute, grid, octree) find the square again just
// past the origin (bvh, kdop and Embree do not only because the flat box is entered at negative
// t). Offsets in ulps of max(max|p|, offset_scale) (the triangle's vertices) avoid it with every
// backend.
TEST(StressSelfIntersection, LargeTriangleNearOriginEveryBackend) {
    for (const char* accel : {"brute", "grid", "octree", "kdop", "bvh", "embree"})
        for (double s : kScales) {
            SelfIntersectionConfig c = tilted_quad(accel, s, 200);
            c.gap_ulps = kGuaranteedGapUlps;
            const SelfIntersectionResult r = probe_self_intersection(c);
            const std::string what = label(c);
            EXPECT_GT(r.rays[0] + r.rays[1] + r.rays[2], 2000u) << what;
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(r.self_hits[k], 0u) << what << " kind " << k;
                EXPECT_EQ(r.neighbour_misses[k], 0u) << what << " kind " << k;
            }
            EXPECT_LE(r.max_offset_ulps, double(kGuaranteedGapUlps)) << what;
        }
}

// The probe above with the unit of the point alone: brute force re-hits the square from points
// near the origin, so the test above can fail.
TEST(StressSelfIntersection, PointOnlyUnitSelfHitsLargeTriangles) {
    SelfIntersectionConfig c = tilted_quad("brute", 1.0, 200);
    c.offset = [](const Vec3f& p, float, const Vec3f& n) { return offset_ray_origin(p, 0.f, n); };
    const SelfIntersectionResult r = probe_self_intersection(c);
    EXPECT_GT(r.self_hits[0] + r.self_hits[1] + r.self_hits[2], 0u);
}

// Every neighbour surface 4 ulps away must be hit, with no self-hit. With float traversal no
// offset does both (docs/numerical-stability.md, section 1); the double-precision path's policy
// (kDoubleRayOffset: half an ulp, origins 0.5 ... 2.5 units away) does, on the tessellated sphere
// (flat and smooth normals), the analytic sphere and the large square through the world origin,
// at every resolvable scale and translation. Collapsed objects (under 16 float steps across) are
// not surfaces at float precision: there only the float policy is self-hit free.
TEST(StressSelfIntersection, DoublePathHitsNeighboursFourUlpsAway) {
    for (int surface = 0; surface < 4; ++surface)
        for (double t : kTranslations)
            for (double s : kScales) {
                if (!resolvable(s, t)) continue;
                if (surface == 3 && t != 0.0) continue;  // the square is always through the origin
                SelfIntersectionConfig c;
                if (surface == 3) {
                    c = tilted_quad(s < 1.0 ? "brute:precision=double" : "bvh:precision=double", s, 200);
                } else {
                    c.accel = "bvh:precision=double";
                    c.surface = surface == 2 ? ProbeSurface::AnalyticSphere : ProbeSurface::MeshSphere;
                    c.smooth_normals = surface == 1;
                    c.translation = t;
                    c.points = 200;
                    c.directions = 6;
                    c.seed = uint64_t(11 + surface);
                }
                c.scale = s;
                c.gap_ulps = 4.0;
                const SelfIntersectionResult r = probe_self_intersection(c);
                const std::string what = label(c);
                EXPECT_GT(r.rays[0] + r.rays[1], 1000u) << what;
                EXPECT_GT(r.min_offset_ulps, 0.0) << what;
                for (int k = 0; k < 3; ++k) EXPECT_EQ(r.self_hits[k], 0u) << what << " kind " << k;
                EXPECT_EQ(r.neighbour_misses[0], 0u) << what << " reflection";
                EXPECT_EQ(r.neighbour_misses[1], 0u) << what << " refraction";
                if (!c.smooth_normals) {  // lifted shadow origins are not offsets (see above)
                    EXPECT_EQ(r.neighbour_misses[2], 0u) << what << " shadow";
                }
            }
}

// The policies belong to the traversal: the float path with the double path's half-ulp offset
// re-hits its own surface (and with its own 4-ulp offset skips 4-ulp neighbours), so the test
// above can fail and the integrator must take the policy from the accelerator.
TEST(StressSelfIntersection, FloatPathNeedsItsOwnPolicy) {
    SelfIntersectionConfig c;
    c.accel = "bvh";
    c.points = 300;
    c.directions = 6;
    c.gap_ulps = 4.0;
    c.offset = [](const Vec3f& p, float scale, const Vec3f& n) { return kDoubleRayOffset.origin(p, scale, n); };
    const SelfIntersectionResult half = probe_self_intersection(c);
    EXPECT_GT(half.self_hits[0] + half.self_hits[1] + half.self_hits[2], 0u);
    // bvh's own policy: no self-hit, but some 4-ulp neighbours skipped (where the gap is 4 offset
    // units, not 8: points in the same binade as the object's largest coordinate).
    c.offset = nullptr;
    c.points = 100;
    uint64_t misses = 0;
    for (double t : kTranslations)
        for (double s : kScales) {
            if (!resolvable(s, t)) continue;
            c.scale = s;
            c.translation = t;
            const SelfIntersectionResult own = probe_self_intersection(c);
            EXPECT_EQ(own.self_hits[0] + own.self_hits[1] + own.self_hits[2], 0u) << label(c);
            misses += own.neighbour_misses[0] + own.neighbour_misses[1];
        }
    EXPECT_GT(misses, 0u);
}

// In the collapsed case s = 1e-4 at t = 1e3 the 12-ulp gap is ~9 times the object's size: the
// inner neighbour would have a negative scale (a mirrored sphere outside A, crossed by outward
// shadow rays as well as B, so shadow rays would count two crossings that are the probe's, not
// the accelerator's). The probe leaves it out.
TEST(StressSelfIntersection, CollapsedCasesHaveNoInnerNeighbour) {
    for (const char* accel : {"bvh", "embree"})
        for (bool analytic : {false, true}) {
            SelfIntersectionConfig c;
            c.accel = accel;
            c.surface = analytic ? ProbeSurface::AnalyticSphere : ProbeSurface::MeshSphere;
            c.scale = 1e-4;
            c.translation = 1e3;
            c.points = 300;
            c.gap_ulps = kGuaranteedGapUlps;
            const SelfIntersectionResult r = probe_self_intersection(c);
            EXPECT_FALSE(r.inner_neighbour) << label(c);
            EXPECT_GT(r.rays[2], 1000u) << label(c);
            EXPECT_EQ(r.shadow_double_counts, 0u) << label(c);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(r.self_hits[k], 0u) << label(c) << " kind " << k;
        }
    SelfIntersectionConfig resolvable_case;  // C is there whenever the object is resolvable
    resolvable_case.scale = 1e-2;
    resolvable_case.points = 50;
    EXPECT_TRUE(probe_self_intersection(resolvable_case).inner_neighbour);
}

// Hit-point error: the integrator's float hit point (SceneView, after the Embree or in-house
// float hit) against the exact point of the double-precision reference; error in ulp(max|p|).
TEST(StressHitError, FloatHitPointsWithinFewUlps) {
    for (const char* accel : {"bvh", "embree"})
        for (bool sphere : {false, true})
            for (double t : kTranslations)
                for (double s : kScales) {
                    if (!resolvable(s, t)) continue;
                    HitErrorResult r = probe_hit_error(accel, sphere, s, t, 1000, 3);
                    const std::string what = std::string(accel) + (sphere ? " sphere" : " mesh") +
                                             " s=" + std::to_string(s) + " t=" + std::to_string(t);
                    EXPECT_GT(r.both_hit, 500u) << what;
                    EXPECT_LE(r.miss_mismatch, r.rays / 100) << what;  // grazing rays at the silhouette
                    const Distribution d = distribution(r.ulp_error);
                    // Bounds from docs/numerical-stability.md: median <= 1.9, max <= 20 ulps for
                    // triangles (float barycentrics move the point along the surface), max <= 10
                    // for spheres (t error along the ray before the re-projection).
                    EXPECT_LE(d.median, 2.5) << what;
                    EXPECT_LE(d.max, sphere ? 16.0 : 32.0) << what;
                    std::vector<double> rel = r.rel_error;
                    EXPECT_LE(distribution(rel).max, 3e-6) << what;
                }
}

}  // namespace
}  // namespace whitted::stress
