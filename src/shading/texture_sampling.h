// Texture lookups: wrap modes, nearest/bilinear filtering, MIP selection, KHR_texture_transform.
//
// Every lookup is pure (no allocation, no shared mutable state), so any number of threads may
// sample the same Texture. Texels are 8-bit; sRGB textures are decoded per texel through a
// 256-entry table before filtering, so results are always linear RGBA (alpha is never decoded).
#pragma once

#include <cstdint>

#include "scene/scene.h"

namespace whitted {

/// Applies KHR_texture_transform: uv' = offset + R(rotation) * (scale * uv) with
/// R(a) * (u, v) = (cos a * u + sin a * v, -sin a * u + cos a * v) (see docs/materials.md).
Vec2f apply_texture_transform(const TextureTransform& xf, Vec2f uv);

/// Linear RGBA at uv; `lod` is the MIP level (0 = full resolution, fractional = trilinear when
/// the texture uses mips). sRGB textures are decoded to linear before filtering.
/// lod <= 0 filters with mag_filter, lod > 0 with min_filter; non-finite uv or lod count as 0.
/// A texture without levels returns (1, 1, 1, 1).
Vec4f sample_texture(const Texture& texture, Vec2f uv, float lod = 0.f);

/// Procedural checkerboard (scene.h: Checker) at UV `uv` or, for a world-space checker, at the
/// world point `p` with unit normal `n`. `width` is the footprint's width in UV units (world
/// units for world-space checkers; 0 = point sample): UV-space checkers are box-filtered over it
/// in closed form (integral of the square wave, as pbrt-v3's Checkerboard2DTexture), so distant
/// squares fade to the mean color instead of aliasing; footprints of 2 squares or more return the
/// mean. World-space checkers are evaluated a small step inside the surface (1e-4 size, or 16 ulps
/// of the point's largest coordinate when that is more), so faces lying on a cell boundary pick
/// one cell wherever they are.
Color sample_checker(const Checker& checker, Vec2f uv, const Vec3f& p, const Vec3f& n, float width = 0.f);

/// Fills texture.levels[1..] from levels[0] by 2x2 box filtering in linear space.
/// Each level is max(1, floor(size / 2)) of the previous one, down to 1x1. Each destination
/// texel averages the source texels its footprint covers, weighted by overlap: exactly the 2x2
/// box for even sizes, and no texel dropped for odd ones (5 -> 2: weights 1, 1, 1/2 | 1/2, 1, 1).
/// Existing levels[1..] are replaced; deterministic.
void build_mip_levels(Texture& texture);

/// sRGB transfer -> linear for an 8-bit value (table lookup, exact IEC 61966-2-1 curve).
float srgb8_to_linear(uint8_t v);

/// Linear -> sRGB transfer, rounded to the nearest 8-bit code; input clamped to [0, 1], NaN -> 0.
/// Looked up among the 255 code thresholds of linear_to_srgb8_formula (the same codes, without a
/// pow per value: MIP levels of sRGB textures encode every texel).
uint8_t linear_to_srgb8(float v);

/// The definition linear_to_srgb8 follows: the IEC 61966-2-1 curve in double, rounded.
uint8_t linear_to_srgb8_formula(float v);

}  // namespace whitted
