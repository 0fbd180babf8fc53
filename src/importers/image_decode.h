// Decoding of texture images (PNG, JPEG: the glTF core formats; WebP: EXT_texture_webp) with limits checked from the
// header before the decoder allocates anything (private to importers/ and the fuzz harnesses).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace whitted {

/// Largest image side accepted, in pixels (docs/fuzzing.md "Limits").
constexpr int kMaxImageSide = 32768;

/// Width and height from a PNG (IHDR), JPEG (first SOFn) or WebP header without decoding; false
/// for other formats or a header cut short.
bool image_size_from_header(const uint8_t* bytes, size_t size, int& width, int& height);

/// Bytes a decode of a width x height image holds at its peak: the decoder's copy (up to 16-bit
/// RGBA), the RGBA8 level and its MIP chain.
size_t decoded_image_bytes(int width, int height);

/// Checks header dimensions against kMaxImageSide and `max_memory`; returns an empty string
/// when the image may be decoded, else the reason (one line, no location).
std::string check_image_size(int width, int height, size_t max_memory);

/// Decodes PNG/JPEG (stb_image; 16-bit images rounded to 8) or WebP (libwebp) bytes to RGBA8 after checking the
/// header dimensions (image_size_from_header(), check_image_size()); throws whitted::Error at
/// `loc` naming `label` when the header is refused or decoding fails.
MipLevel decode_image_rgba8(const uint8_t* bytes, size_t size, size_t max_memory, const FileLoc& loc,
                            const std::string& label);

}  // namespace whitted
