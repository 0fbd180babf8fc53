// Image files for scene-file textures, read through OpenImageIO (src/core/image_files.h,
// loaded on first use; private to importers/).
#pragma once

#include <cstddef>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace whitted {

struct LoadedImage {
    MipLevel level;              ///< RGBA8, top row first
    bool float_data = false;     ///< the file holds floating-point (linear) values: `level` is
                                 ///< sRGB-encoded from them, so the texture must be srgb = true
};

/// Reads the first subimage of `file` (any format OIIO reads: PNG, JPEG, EXR, TIFF, HDR, ...) into
/// 8-bit RGBA: gray -> RGB, missing alpha = 1, 16-bit values rounded to 8 bits, float values
/// encoded with the sRGB transfer. The size is checked against kMaxImageSide and `max_memory`
/// from the header first. Throws whitted::Error at `loc`.
LoadedImage load_image_file(const std::string& file, size_t max_memory, const FileLoc& loc);

}  // namespace whitted
