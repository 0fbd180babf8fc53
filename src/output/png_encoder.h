// PNG files of display codes, encoded by whitted itself with zlib: rows are filtered and deflated
// in bands on all cores (the pigz scheme: each band a raw deflate stream primed with the previous
// band's last 32 KiB and ended on a byte boundary, the bands' Adler-32 sums combined), so a
// 1920x1080 image takes a few tens of milliseconds instead of OpenImageIO's ~0.3 s single-threaded
// libpng, and writing a PNG does not load OIIO at all. The bytes depend only on the pixels and
// the options, never on the thread count. See docs/performance.md "Output".
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace whitted {

struct PngOptions {
    int level = 2;  ///< zlib level 0..9 (chosen by measurement, docs/measurements/performance.md)
    /// Rows per band (one deflate stream and one IDAT chunk each); 0 = about 64 KiB of pixels.
    int band_rows = 0;
};

/// A PNG of `width` x `height` RGB pixels: `codes` holds 3 samples per pixel, rows top to bottom,
/// one byte each for bits = 8, native-endian uint16_t for bits = 16. `text` becomes tEXt chunks
/// (Latin-1 keys of 1..79 characters; longer keys are cut). Throws whitted::Error on bad
/// arguments or a zlib failure.
std::vector<uint8_t> encode_png(std::span<const uint8_t> codes, int width, int height, int bits,
                                const std::vector<std::pair<std::string, std::string>>& text,
                                const PngOptions& options = {});

}  // namespace whitted
