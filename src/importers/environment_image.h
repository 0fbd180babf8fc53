// Environment maps from files (OpenImageIO: EXR, HDR, TIFF, PNG, JPEG) and the bundled names
// (docs/environment.md). Read through src/core/image_files.h (OIIO, loaded on first use).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scene/environment.h"

namespace whitted {

/// The names of the maps bundled in assets/environments/ (studio first: the default).
const std::vector<std::string>& bundled_environment_names();

/// A path to an existing file is returned as is; a bundled name gives
/// <source tree>/assets/environments/<name>.exr; anything else throws whitted::Error listing
/// the bundled names.
std::string resolve_environment_name(const std::string& name);

/// True when `path` is one of the bundled maps (resolve_environment_name of a bundled name). Their
/// few slightly negative texels are reported at info level, not as a warning of every render.
bool is_bundled_environment(const std::string& path);

/// Bytes loading and using a width x height map with `channels` channels costs at its peak:
/// the file's float pixels, the image (12 bytes a texel) and EnvironmentMap::estimated_bytes.
size_t environment_load_bytes(int width, int height, int channels);

/// Reads the first subimage of `path` as linear RGB: the first 3 channels (grey -> RGB);
/// floating-point files as they are, 8- and 16-bit ones decoded from sRGB. Throws
/// whitted::Error (one line naming the file) for a missing file, a file that is not an image,
/// an empty image, or one costing more than `max_memory_bytes` (environment_load_bytes).
/// Appends to `warnings`: an aspect other than 2:1; negative, NaN or infinite texels, which are
/// set to 0 (one warning with their count).
EnvironmentImage load_environment_image(const std::string& path, size_t max_memory_bytes,
                                        std::vector<std::string>& warnings);

}  // namespace whitted
