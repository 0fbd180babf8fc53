// Texture lookups: wrap modes, nearest/bilinear filtering, MIP selection, KHR_texture_transform.
#pragma once

#include "renderer/scene/scene.h"

namespace whitted {

/// Applies KHR_texture_transform (uv' = T * R * S * uv).
Vec2f apply_texture_transform(const TextureTransform& xf, Vec2f uv);

/// Linear RGBA at uv; `lod` is the MIP level (0 = full resolution, fractional = trilinear when
/// the texture uses mips). sRGB textures are decoded to linear before filtering.
Vec4f sample_texture(const Texture& texture, Vec2f uv, float lod = 0.f);

/// Fills texture.levels[1..] from levels[0] by 2x2 box filtering in linear space.
void build_mip_levels(Texture& texture);

/// sRGB transfer -> linear for an 8-bit value (table lookup).
float srgb8_to_linear(uint8_t v);

}  // namespace whitted
