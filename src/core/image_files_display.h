// JPEG and TIFF files written in process (libjpeg-turbo, libtiff): display-referred 8/16-bit RGB,
// without loading the OIIO module (image_files.cpp sends "jpeg" and "tiff" here).
#pragma once

#include <string>

#include "core/image_files.h"

namespace whitted {

/// As write_image_file with format_name "jpeg": 8-bit RGB, quality from the "CompressionQuality"
/// attribute (default 98, as OpenImageIO) with 4:2:0 chroma; "Software" and the other attributes go into one
/// comment marker ("key: value" lines).
void write_jpeg_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)());

/// As write_image_file with format_name "tiff": 8- or 16-bit RGB in strips of 32 rows, each
/// a zlib stream (Adobe Deflate; libdeflate level from "compression" = "zip" (1) or "zip:N", 1-12,
/// default 1) of the rows with the horizontal predictor, strips compressed on all cores; or, with
/// "compression" = "none", the rows as they are. Another compression name throws
/// (tiff_compression_error). "Software" and "ImageDescription" attributes become tags, the others
/// join ImageDescription. The file's bytes do not depend on the thread count.
void write_tiff_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)());

/// Empty when `name` is a TIFF compression write_tiff_file takes (none, zip, zip:1 to zip:12),
/// else why not (one line).
std::string tiff_compression_error(const std::string& name);

}  // namespace whitted
