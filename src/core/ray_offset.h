// Self-intersection avoidance for secondary rays (Wächter & Binder, "A Fast and Robust Method for
// Avoiding Self-Intersection", Ray Tracing Gems 2019; rounding away as pbrt-v4 OffsetRayOrigin).
// The origin moves along the unit geometric normal by kOffsetUlps ulps of m = max(max|p|, scale),
// where `scale` is the magnitude of the hit primitive's own coordinates
// (SurfacePoint::offset_scale): the watertight triangle test's rounding grows with the vertices'
// coordinates, not with |p|, as pbrt-v4's pError does.
//
// Unlike Wächter & Binder: one unit for the three components instead of 256 ulps of each
// coordinate (which skips near neighbour surfaces), and no absolute offset near the world origin
// (too large for small scenes). The unit is at least FLT_MIN, so flush-to-zero cannot cancel it.
// The guarantee and why 4 ulps: docs/numerical-stability.md, section 1, checked by
// tests/stress/test_stress_self_intersection.cpp. Backends whose rounding needs another distance
// say so through Accelerator::ray_offset() (src/accel/accelerator.h).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/vecmath.h"

namespace whitted {

namespace detail {
constexpr float kOffsetUlps = 4.f;  ///< distance moved along the normal, in ulps of max(max|p|, scale)

/// Spacing of floats at max(max|p|, scale): 2^(exponent - 23), at least FLT_MIN.
/// std::max, not std::fmax, which may be a libm call; they differ only for NaN, where the origin
/// is NaN anyway.
inline float offset_unit(const Vec3f& p, float scale) {
    const float m = std::max(std::max(std::fabs(p.x), scale), std::max(std::fabs(p.y), std::fabs(p.z)));
    const float binade = std::bit_cast<float>(std::bit_cast<uint32_t>(m) & 0x7f800000u);  // 2^exponent
    return std::max(binade * 0x1p-23f, std::numeric_limits<float>::min());
}

/// x moved by one float step in the direction of `dir` (never into the denormals: from 0 the
/// step is FLT_MIN, which flush-to-zero keeps).
inline float step_towards(float x, float dir) {
    if (dir == 0.f) return x;
    if (x == 0.f) return dir > 0.f ? std::numeric_limits<float>::min() : -std::numeric_limits<float>::min();
    const int32_t bits = std::bit_cast<int32_t>(x);
    return std::bit_cast<float>(bits + (((x > 0.f) == (dir > 0.f)) ? 1 : -1));
}
}  // namespace detail

/// Surfaces at least this many ulps of max(max|p|, scale) in front of an offset origin are always
/// hit (offset + rounding + hit-point error, with a margin; checked by tests/stress).
constexpr float kGuaranteedGapUlps = 12.f;

/// kGuaranteedGapUlps ulps of max(max|p|, scale) as a distance (scale: the hit primitive's
/// SurfacePoint::offset_scale): a secondary ray leaving p meets every surface farther than this
/// from p's surface and may skip nearer ones (the integrator looks for touching dielectrics
/// explicitly).
inline float guaranteed_gap(const Vec3f& p, float scale) { return kGuaranteedGapUlps * detail::offset_unit(p, scale); }

/// Moves p off its surface to the side the unit normal n points to (flip n to leave the other way):
/// `ulps` ulps of max(max|p|, scale) along n, each moved coordinate then rounded one step further
/// away. `scale` is the magnitude of the hit primitive's coordinates (SurfacePoint::offset_scale;
/// 0 = the point alone). The renderer uses kOffsetUlps (the overload below); other distances are
/// for the stress sweep (`whitted bench stability --offset-ulps`).
inline Vec3f offset_ray_origin(const Vec3f& p, float scale, const Vec3f& n, float ulps) {
    const float d = ulps * detail::offset_unit(p, scale);
    Vec3f o = p + n * d;
    for (int k = 0; k < 3; ++k) o[k] = detail::step_towards(o[k], n[k]);
    return o;
}

/// offset_ray_origin by kOffsetUlps: what every secondary ray of the renderer uses.
inline Vec3f offset_ray_origin(const Vec3f& p, float scale, const Vec3f& n) {
    return offset_ray_origin(p, scale, n, detail::kOffsetUlps);
}

}  // namespace whitted
