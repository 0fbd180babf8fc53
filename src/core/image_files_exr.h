// EXR files through OpenEXR directly (image_files.cpp sends .exr here, everything else to the
// OIIO module): light enough to link into every process.
#pragma once

#include <memory>
#include <string>

#include "core/image_files.h"

namespace whitted {

/// Whether the file starts with the EXR magic number.
bool is_exr_file(const std::string& path);

/// As open_image_file, for an EXR file (scanline or tiled, first part).
std::unique_ptr<ImageFileReader> open_exr_file(const std::string& path);

/// Empty when `name` is a "compression" write_exr_file takes (lossless: none, rle, zips, zip, piz;
/// zip and zips with an optional zlib level, "zip:6"), else why not, for one error line. A desc
/// without "compression" is written zip:1.
std::string exr_compression_error(const std::string& name);

/// As write_image_file with format_name "openexr"; "compression" among the attributes picks the
/// codec (exr_compression_error; another value throws), every other attribute becomes a string
/// header attribute.
void write_exr_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)());

}  // namespace whitted
