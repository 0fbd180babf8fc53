// What `whitted bench env`'s split measurement and the environment tests compare irradiance with:
// fixed random normals and the largest per-channel relative error.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/vecmath.h"

namespace whitted {

/// `count` unit directions, uniform on the sphere, from a fixed seed.
inline std::vector<Vec3f> random_directions(int count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> g;
    std::vector<Vec3f> out;
    while (int(out.size()) < count) {
        const Vec3f d{g(rng), g(rng), g(rng)};
        if (length(d) > 1e-3f) out.push_back(normalize(d));
    }
    return out;
}

/// The largest of |got - want| / |want| over the three channels (|want| at least 1e-12).
inline float max_relative_error(const Color& got, const Color& want) {
    float e = 0.f;
    for (int c = 0; c < 3; ++c) e = std::max(e, std::fabs(got[c] - want[c]) / std::max(std::fabs(want[c]), 1e-12f));
    return e;
}

}  // namespace whitted
