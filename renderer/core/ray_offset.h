// Self-intersection avoidance for secondary rays (Wächter & Binder, "A Fast and Robust Method
// for Avoiding Self-Intersection", Ray Tracing Gems, 2019): the origin moves along the geometric
// normal by a fixed number of ulps of each coordinate, so the offset scales with the magnitude of
// the hit point; near the origin, where ulps are tiny, a small absolute offset takes over.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "renderer/core/vecmath.h"

namespace whitted {

namespace detail {
constexpr float kOffsetOrigin = 1.f / 32.f;        ///< below this |coordinate|, offset absolutely
constexpr float kOffsetFloatScale = 1.f / 65536.f; ///< absolute offset scale near the origin
constexpr float kOffsetIntScale = 256.f;           ///< ulps of offset per unit normal component

inline float offset_component(float p, float n) {
    int32_t of = int32_t(kOffsetIntScale * n);
    int32_t bits = std::bit_cast<int32_t>(p);
    float pi = std::bit_cast<float>(bits + ((p < 0.f) ? -of : of));
    return std::fabs(p) < kOffsetOrigin ? p + kOffsetFloatScale * n : pi;
}
}  // namespace detail

/// Moves p off its surface to the side the unit normal n points to (flip n to leave the other way).
inline Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n) {
    return {detail::offset_component(p.x, n.x), detail::offset_component(p.y, n.y),
            detail::offset_component(p.z, n.z)};
}

}  // namespace whitted
