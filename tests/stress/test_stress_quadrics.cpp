// Analytic quadrics under stress (docs/numerical-stability.md, section 8): capped cylinders,
// capped truncated cones and discs at scales 1e-2 .. 1e4 and up to 1e5 from the origin, hit from
// every angle down to grazing, on their sides, caps and exactly on their rims; secondary rays
// spawned as the integrator spawns them. Bounded for CI; `whitted bench stability` prints the
// same probe's figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "benchmarks/stability_probes.h"

namespace whitted::stress {
namespace {

const char* kind_name(QuadricKind k) { return k == QuadricKind::Cylinder ? "cylinder" : k == QuadricKind::Cone ? "cone" : "disc"; }

TEST(StressQuadrics, NoSelfHitsLeaksOrLostHitsAtAnyScale) {
    for (const std::string accel : {"bvh", "embree"})
        for (const QuadricKind kind : {QuadricKind::Cylinder, QuadricKind::Cone, QuadricKind::Disc})
            for (const double s : {1e-2, 1.0, 1e2, 1e4})
                for (const double t : {0.0, 1e3, 1e5}) {
                    if (s < 1e-6 * t) continue;  // collapsed in float: nothing to resolve
                    QuadricProbeConfig c;
                    c.accel = accel;
                    c.kind = kind;
                    c.scale = s;
                    c.translation = t;
                    c.points = 1500;
                    c.directions = 8;
                    c.seed = 11;
                    QuadricProbeResult r = probe_quadric(c);
                    const std::string what = accel + " " + kind_name(kind) + " s=" + std::to_string(s) + " t=" + std::to_string(t);
                    SCOPED_TRACE(what);
                    const Distribution pe = distribution(r.point_error_ulps);
                    const Distribution ne = distribution(r.normal_error_rad);
                    const Distribution se = distribution(r.surface_error_ulps);
                    std::printf("[ quadric ] %-36s points %4llu, self-hits %llu/%llu/%llu, leaks %llu, misses %llu, "
                                "inward unjudged %llu, point error median %.2f max %.2f ulp (off the surface %.2f), normal error max %.1e rad\n",
                                what.c_str(), (unsigned long long)r.points, (unsigned long long)r.self_hits[0],
                                (unsigned long long)r.self_hits[1], (unsigned long long)r.self_hits[2],
                                (unsigned long long)r.leaks, (unsigned long long)r.camera_misses,
                                (unsigned long long)r.inward_unjudged, pe.median, pe.max, se.max, ne.max);
                    EXPECT_GT(r.points, c.points / 2);
                    EXPECT_EQ(r.camera_misses, 0u);
                    EXPECT_EQ(r.self_hits[0], 0u);
                    EXPECT_EQ(r.self_hits[1], 0u);
                    EXPECT_EQ(r.self_hits[2], 0u);
                    EXPECT_EQ(r.leaks, 0u);
                    // Along the surface the float t moves the point by its rounding (in ulps of the
                    // point or the ray's length, the larger); off it, what the ray offset covers, at
                    // most a rounding.
                    EXPECT_LE(pe.max, 4.0);
                    EXPECT_LE(se.max, 1.0);
                    EXPECT_LT(ne.max, 1e-5);
                    // Most inward rays are judged (those near a rim are not) where the shape spans
                    // at least a thousandth of its distance from the origin.
                    if (s >= 1e-3 * t && kind != QuadricKind::Disc) {
                        EXPECT_LT(r.inward_unjudged, r.rays[1] / 2);
                    }
                }
}

}  // namespace
}  // namespace whitted::stress
