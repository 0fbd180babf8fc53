// Self-intersection avoidance for secondary rays: the ray origin moves off the surface along the
// geometric normal by a distance that scales with the magnitude of the coordinates involved, as in
// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems,
// 2019), and is rounded away from the surface as in pbrt-v4 (OffsetRayOrigin).
//
// The unit: ulp(m), the float spacing at m = max(max|p|, scale), where `scale` is the magnitude of
// the hit primitive's own coordinates (SurfacePoint::offset_scale: the largest |coordinate| of a
// triangle's world-space vertices; a sphere's radius; see SceneView). The accelerators' rounding
// scales with the primitive, not with the point: the float watertight triangle test forms v_i - o
// for each vertex, so on a large triangle near the world origin its t error is a few ulps of the
// vertices' coordinates, far more than ulps of the small |p| (pbrt-v4's pError grows with the
// vertices for the same reason). With the unit of |p| alone, shadow rays leaving whitted1980's
// floor near the origin found the floor again at t ~ 1e-8 on the backends without a per-primitive
// box test (docs/numerical-stability.md, section 1 and "Fixed").
//
// Differences from Wächter & Binder, both found by the stress suite (docs/numerical-stability.md):
//   - The distance is kOffsetUlps ulps of m along the unit normal (one scale for the three
//     components), not 256 ulps of each coordinate: the hit point's error is a few ulps of its
//     largest coordinate whatever the normal, and 256 ulps skipped neighbour surfaces up to
//     ~250 ulps away (contact shadows, thin gaps).
//   - No absolute offset of 1/65536 near the world origin: it is 15 % of the size of a 1e-4 scene
//     (rays tunnelled through whole objects). Below m ~ 1e-31 the unit is FLT_MIN, so that
//     flush-to-zero / denormals-are-zero (set in every render thread) cannot cancel the offset.
// Guarantee (tests/stress/test_stress_self_intersection.cpp): with SceneView's hit points (computed
// in double, at most ~0.8 ulp(max|p|) off the surface) and its offset_scale, no secondary ray
// re-hits its own surface at any scale from 1e-4 to 1e6 and any translation up to 1e5, on a large
// triangle through the world origin, with every backend, and every surface more than
// kGuaranteedGapUlps ulps of m away in front of the origin is still hit. Why not less than 4 ulps
// (`whitted bench stability --offset-ulps`, docs/numerical-stability.md section 1): 3 ulps still
// self-hits on objects that collapse to a few float steps, 1-2 ulps also on resolvable ones, and
// no offset reaches neighbours 4 ulps away (origins end over a ~3-ulp spread of distances).
// That is float traversal's limit: each accelerator states the offset its rounding needs
// (Accelerator::ray_offset(), RayOffsetPolicy in renderer/accel/accelerator.h), and the
// double-precision backends need only half an ulp, which reaches 4-ulp neighbours.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "renderer/core/vecmath.h"

namespace whitted {

namespace detail {
constexpr float kOffsetUlps = 4.f;  ///< distance moved along the normal, in ulps of max(max|p|, scale)

/// Spacing of floats at max(max|p|, scale): 2^(exponent - 23), at least FLT_MIN.
/// std::max, not std::fmax: without -ffinite-math-only fmaxf is a libm call on every secondary
/// ray (it only differs for NaN, where the origin is NaN anyway).
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
/// hit (measured bound, tests/stress: offset + rounding + hit-point error, with a margin).
constexpr float kGuaranteedGapUlps = 12.f;

/// kGuaranteedGapUlps ulps of max(max|p|, scale) as a distance (scale: the hit primitive's
/// SurfacePoint::offset_scale): a secondary ray leaving p meets every surface farther than this
/// from p's surface and may skip nearer ones (touching dielectrics look for those explicitly,
/// renderer/integrator/whitted_integrator.cpp).
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
