// The fixed direction sets (src/shading/sample_sets.h): the occlusion grid's cells are equal
// shares of the cosine-weighted hemisphere, its neighbours are mutual, and the smooth frame is
// orthonormal and turns continuously with the normal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "shading/sample_sets.h"

namespace whitted {
namespace {

// Under the cosine distribution E[cos theta] = 2/3 and E[cos^2 theta] = 1/2: the cells' directions,
// each an equal share at its cell's mean cos(theta), give the first for any grid and the second
// closer as the grid gets finer; every one is a unit vector above the horizon.
TEST(SampleSets, GridCellsAreEqualCosineShares) {
    for (const int count : {4, 36, 256}) {
        const HemisphereGrid g = cosine_grid(count);
        EXPECT_EQ(int(g.size()), g.n * g.n);
        EXPECT_EQ(g.n, int(std::lround(std::sqrt(double(count)))));
        double m1 = 0.0, m2 = 0.0;
        for (const Vec3f& d : g.centres) {
            EXPECT_NEAR(length(d), 1.f, 1e-5f);
            EXPECT_GT(d.z, 0.f);
            m1 += d.z, m2 += double(d.z) * d.z;
        }
        m1 /= double(g.size()), m2 /= double(g.size());
        EXPECT_NEAR(m1, 2.0 / 3.0, 0.005) << count;
        EXPECT_NEAR(m2, 0.5, count >= 256 ? 0.005 : (count >= 36 ? 0.02 : 0.06)) << count;
    }
    EXPECT_EQ(cosine_direction(0.5f, 0.5f), Vec3f(0.f, 0.f, 1.f));  // the square's centre: the pole
}

TEST(SampleSets, NeighboursAreMutualAndShareAnEdge) {
    const HemisphereGrid g = cosine_grid(36);
    for (int k = 0; k < int(g.size()); ++k)
        for (const int n : g.neighbours(k)) {
            if (n < 0) continue;
            const auto back = g.neighbours(n);
            EXPECT_NE(std::find(back.begin(), back.end(), k), back.end()) << k << " " << n;
            EXPECT_EQ(std::abs(k % g.n - n % g.n) + std::abs(k / g.n - n / g.n), 1) << k << " " << n;
        }
}

TEST(SampleSets, SmoothFrameIsOrthonormalAndContinuous) {
    for (int i = 0; i < 200; ++i) {
        const float y = 1.f - 2.f * (float(i) + 0.5f) / 200.f, r = std::sqrt(1.f - y * y), phi = 2.39996f * float(i);
        const Vec3f n(r * std::cos(phi), y, r * std::sin(phi));
        const SmoothFrame f(n);
        EXPECT_NEAR(dot(f.t, f.b), 0.f, 1e-5f);
        EXPECT_NEAR(dot(f.t, f.n), 0.f, 1e-5f);
        EXPECT_NEAR(length(f.t), 1.f, 1e-5f);
        EXPECT_NEAR(length(f.b), 1.f, 1e-5f);
        EXPECT_NEAR(dot(cross(f.t, f.b), f.n), 1.f, 1e-5f);  // right-handed
        // A small turn of the normal turns the frame a little (no flip), here and across n.z = 0.
        const SmoothFrame g(normalize(n + Vec3f(1e-3f, -2e-3f, 1.5e-3f)));
        EXPECT_GT(dot(f.t, g.t), 0.99f) << "normal " << i;
    }
    // The axis-aligned normals of floors and walls are far from the frame's singular axis.
    const SmoothFrame up(Vec3f(0.f, 1.f, 0.f)), up_signed(Vec3f(0.f, 1.f, -0.f));
    EXPECT_EQ(up.t, up_signed.t);
}

}  // namespace
}  // namespace whitted
