// JPEG through libjpeg(-turbo), TIFF through libtiff with strips deflated (libdeflate) in parallel.
#include "core/image_files_display.h"

#include <algorithm>
#include <charconv>
#include <csetjmp>
#include <cstdarg>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <jpeglib.h>
#include <tbb/parallel_for.h>
#include <tiffio.h>
#include <libdeflate.h>

#include "core/error.h"
#include "core/jpeg_errors.h"

namespace whitted {

namespace {

/// Checks what both writers take: RGB, one integer type for every channel.
int checked_bits(const ImageDesc& desc, bool allow_16) {
    if (desc.width <= 0 || desc.height <= 0 || desc.channels() != 3) throw Error("expected a non-empty RGB image");
    const PixelType t = desc.channel_types.front();
    for (PixelType c : desc.channel_types)
        if (c != t) throw Error("channels of different types");
    if (t == PixelType::UInt8) return 8;
    if (t == PixelType::UInt16 && allow_16) return 16;
    throw Error(allow_16 ? "expected 8- or 16-bit channels" : "JPEG supports only 8-bit channels");
}

/// "key: value" lines of every attribute but the ones listed.
std::string other_attributes(const ImageDesc& desc, std::initializer_list<std::string_view> skip) {
    std::string text;
    for (const auto& [key, value] : desc.attributes) {
        if (std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
        text += (text.empty() ? "" : "\n") + key + ": " + value;
    }
    return text;
}

struct FileCloser {
    void operator()(std::FILE* f) const {
        if (f) std::fclose(f);
    }
};

}  // namespace

void write_jpeg_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)()) {
    checked_bits(desc, false);
    int quality = 98;  // OpenImageIO's default: the same pixels as before
    if (const std::string q = desc.attribute("CompressionQuality"); !q.empty()) quality = std::clamp(std::atoi(q.c_str()), 1, 100);
    const std::string comment = other_attributes(desc, {"CompressionQuality"});
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) throw Error(fmt::format("cannot create '{}': {}", path, std::strerror(errno)));
    std::unique_ptr<std::FILE, FileCloser> file(f);
    if (before_pixels) before_pixels();

    jpeg_compress_struct cinfo;
    JpegErrors errors;
    cinfo.err = jpeg_std_error(&errors.mgr);
    errors.mgr.error_exit = jpeg_error_exit;
    // Nothing with a destructor lives between setjmp and the library calls that may jump back.
    if (setjmp(errors.jump)) {
        jpeg_destroy_compress(&cinfo);
        throw Error(fmt::format("JPEG: {}", errors.message));
    }
    jpeg_create_compress(&cinfo);
    jpeg_stdio_dest(&cinfo, f);
    cinfo.image_width = JDIMENSION(desc.width);
    cinfo.image_height = JDIMENSION(desc.height);
    cinfo.input_components = 3;
    cinfo.in_color_space = JCS_RGB;
    jpeg_set_defaults(&cinfo);
    jpeg_set_quality(&cinfo, quality, TRUE);
    jpeg_start_compress(&cinfo, TRUE);
    if (!comment.empty())
        jpeg_write_marker(&cinfo, JPEG_COM, reinterpret_cast<const JOCTET*>(comment.data()), unsigned(std::min<size_t>(comment.size(), 65533)));
    const auto* rows = static_cast<const JSAMPLE*>(pixels);
    const size_t stride = size_t(desc.width) * 3;
    while (cinfo.next_scanline < cinfo.image_height) {
        JSAMPROW row = const_cast<JSAMPLE*>(rows + size_t(cinfo.next_scanline) * stride);
        jpeg_write_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_compress(&cinfo);
    jpeg_destroy_compress(&cinfo);
    const bool flushed = std::fflush(f) == 0 && !std::ferror(f);
    if (!flushed) throw Error(fmt::format("cannot write '{}': {}", path, std::strerror(errno)));
}

namespace {

/// The zlib level a TIFF compression name asks for: "none" -> 0, "zip" -> 1, "zip:N" -> N (1-12);
/// anything else is an error message.
std::string parse_tiff_compression(const std::string& name, int& level) {
    if (name == "none") {
        level = 0;
        return {};
    }
    if (name == "zip") {
        level = 1;
        return {};
    }
    if (name.rfind("zip:", 0) == 0) {
        const std::string digits = name.substr(4);
        int n = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
        if (ec == std::errc() && end == digits.data() + digits.size() && !digits.empty() && n >= 1 && n <= 12) {
            level = n;
            return {};
        }
        return fmt::format("TIFF compression '{}': the zlib level is 1 to 12", name);
    }
    return fmt::format("unknown TIFF compression '{}' (lossless: none, zip, zip:1 to zip:12)", name);
}

}  // namespace

std::string tiff_compression_error(const std::string& name) {
    int unused = 0;
    return parse_tiff_compression(name, unused);
}

void write_tiff_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)()) {
    const int bits = checked_bits(desc, true);
    int level = 1;
    if (const std::string name = desc.attribute("compression"); !name.empty())
        if (const std::string why = parse_tiff_compression(name, level); !why.empty()) throw Error(why);
    const bool deflate = level > 0;
    constexpr int kRowsPerStrip = 32;
    const size_t bytes_per_sample = size_t(bits / 8);
    const size_t row_bytes = size_t(desc.width) * 3 * bytes_per_sample;
    const int strips = (desc.height + kRowsPerStrip - 1) / kRowsPerStrip;

    // Each strip: the horizontal predictor (each sample minus the one of the pixel to its left,
    // modulo 2^bits, in native order as libtiff writes it) and its own zlib stream, on all cores.
    std::vector<std::vector<uint8_t>> compressed(static_cast<size_t>(deflate ? strips : 0));
    std::vector<char> failures(static_cast<size_t>(strips), 0);
    if (deflate) tbb::parallel_for(0, strips, [&](int s) {
        const int y0 = s * kRowsPerStrip, y1 = std::min(desc.height, y0 + kRowsPerStrip);
        std::vector<uint8_t> raw(size_t(y1 - y0) * row_bytes);
        for (int y = y0; y < y1; ++y) {
            const uint8_t* src = static_cast<const uint8_t*>(pixels) + size_t(y) * row_bytes;
            uint8_t* dst = raw.data() + size_t(y - y0) * row_bytes;
            if (bits == 8) {
                for (size_t i = 0; i < row_bytes; ++i) dst[i] = uint8_t(src[i] - (i >= 3 ? src[i - 3] : 0));
            } else {
                const size_t n = row_bytes / 2;
                for (size_t i = 0; i < n; ++i) {
                    uint16_t v, left = 0;
                    std::memcpy(&v, src + 2 * i, 2);
                    if (i >= 3) std::memcpy(&left, src + 2 * (i - 3), 2);
                    const auto d = uint16_t(v - left);
                    std::memcpy(dst + 2 * i, &d, 2);
                }
            }
        }
        libdeflate_compressor* c = libdeflate_alloc_compressor(level);
        if (!c) {
            failures[size_t(s)] = 1;
            return;
        }
        std::vector<uint8_t>& out = compressed[size_t(s)];
        out.resize(libdeflate_zlib_compress_bound(c, raw.size()));
        const size_t size = libdeflate_zlib_compress(c, raw.data(), raw.size(), out.data(), out.size());
        libdeflate_free_compressor(c);
        failures[size_t(s)] = size == 0;
        out.resize(size);
    });
    for (char failed : failures)
        if (failed) throw Error(fmt::format("libdeflate: cannot compress a TIFF strip at level {}", level));

    // libtiff's warnings and errors would go to stderr: the first error becomes our message.
    static thread_local std::string tiff_error;
    tiff_error.clear();
    struct Handlers {  // libtiff's handlers are process-wide: the previous ones come back after
        TIFFErrorHandler error = TIFFSetErrorHandler([](const char* module, const char* fmt_, va_list ap) {
            char buf[512];
            std::vsnprintf(buf, sizeof buf, fmt_, ap);
            if (tiff_error.empty()) tiff_error = std::string(module ? module : "libtiff") + ": " + buf;
        });
        TIFFErrorHandler warning = TIFFSetWarningHandler(nullptr);
        ~Handlers() {
            TIFFSetErrorHandler(error);
            TIFFSetWarningHandler(warning);
        }
    } handlers;
    TIFF* tif = TIFFOpen(path.c_str(), "w");
    if (!tif) throw Error(fmt::format("cannot create '{}': {}", path, tiff_error.empty() ? std::strerror(errno) : tiff_error));
    struct Closer {
        TIFF* t;
        ~Closer() { TIFFClose(t); }
    } closer{tif};
    if (before_pixels) before_pixels();
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, uint32_t(desc.width));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, uint32_t(desc.height));
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 3);
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, deflate ? COMPRESSION_ADOBE_DEFLATE : COMPRESSION_NONE);
    if (deflate) TIFFSetField(tif, TIFFTAG_PREDICTOR, PREDICTOR_HORIZONTAL);
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, uint32_t(kRowsPerStrip));
    if (const std::string sw = desc.attribute("Software"); !sw.empty()) TIFFSetField(tif, TIFFTAG_SOFTWARE, sw.c_str());
    std::string description = desc.attribute("ImageDescription");
    if (const std::string others = other_attributes(desc, {"Software", "ImageDescription", "compression"}); !others.empty())
        description += (description.empty() ? "" : "\n") + others;
    if (!description.empty()) TIFFSetField(tif, TIFFTAG_IMAGEDESCRIPTION, description.c_str());
    for (int s = 0; s < strips; ++s) {
        // Uncompressed: the strip is the rows themselves.
        const int rows = std::min(desc.height - s * kRowsPerStrip, kRowsPerStrip);
        void* data = deflate ? static_cast<void*>(compressed[size_t(s)].data())
                             : const_cast<uint8_t*>(static_cast<const uint8_t*>(pixels) + size_t(s) * kRowsPerStrip * row_bytes);
        const auto size = tmsize_t(deflate ? compressed[size_t(s)].size() : size_t(rows) * row_bytes);
        if (TIFFWriteRawStrip(tif, uint32_t(s), data, size) < 0)
            throw Error(fmt::format("cannot write '{}': {}", path, tiff_error.empty() ? "strip write failed" : tiff_error));
    }
    if (!TIFFWriteDirectory(tif) || !tiff_error.empty())
        throw Error(fmt::format("cannot write '{}': {}", path, tiff_error.empty() ? "directory write failed" : tiff_error));
}

}  // namespace whitted
