// Texture image decoding with header limits: a small file must not be able to claim a
// 100000 x 100000 image and have the decoder allocate it (docs/fuzzing.md).

#include "importers/image_decode.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <webp/decode.h>

#include "core/jpeg_errors.h"

// stb_image compiled here (Debian's libstb-dev header), not the copy inside the tinygltf shared
// library: this one is built with the project's flags, so sanitizer and fuzzing builds instrument
// it, and it is cut down to PNG with the side limit whitted enforces. JPEG goes through
// libjpeg-turbo (below): stb_image 2.27's JPEG decoder writes out of bounds on a Huffman table of
// more than 256 codes (tests/data/fuzz-regressions/image/ubsan-stbi-huffman-*.jpg).
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#define STBI_MAX_DIMENSIONS 32768  // = kMaxImageSide (checked below)
// stb_image 2.27 calls memcpy(NULL, src, 0) for a PNG whose first IDAT chunk is empty (no buffer
// allocated yet): undefined behaviour that UBSan reports (regression file
// tests/data/fuzz-regressions/image/ubsan-stbi-getn-null-memcpy.png). Inside stb only, memcpy
// skips empty copies. <cstring> is included above, so stb's own #include <string.h> is a no-op.
namespace {
void* stbi_memcpy_nonempty(void* dst, const void* src, size_t n) { return n != 0 ? std::memcpy(dst, src, n) : dst; }
}  // namespace
#define memcpy stbi_memcpy_nonempty
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop
#undef memcpy

namespace whitted {

static_assert(STBI_MAX_DIMENSIONS == kMaxImageSide, "stb_image's limit is whitted's");

bool is_webp(const uint8_t* p, size_t n) {
    return p != nullptr && n >= 12 && std::memcmp(p, "RIFF", 4) == 0 && std::memcmp(p + 8, "WEBP", 4) == 0;
}

namespace {
bool is_jpeg(const uint8_t* p, size_t n) { return n >= 2 && p[0] == 0xFF && p[1] == 0xD8; }  // SOI
}  // namespace

bool image_size_from_header(const uint8_t* p, size_t n, int& w, int& h) {
    if (p == nullptr) return false;
    // WebP (EXT_texture_webp): libwebp reads the size from the VP8/VP8L/VP8X header alone.
    if (is_webp(p, n)) return WebPGetInfo(p, n, &w, &h) != 0;
    auto be16 = [&](size_t i) { return (uint32_t(p[i]) << 8) | p[i + 1]; };
    auto be32 = [&](size_t i) { return (be16(i) << 16) | be16(i + 2); };
    // PNG: the signature, then IHDR as the first chunk (PNG spec 11.2.2).
    if (n >= 24 && std::memcmp(p, "\x89PNG\r\n\x1a\n", 8) == 0 && std::memcmp(p + 12, "IHDR", 4) == 0) {
        w = int(std::min<uint32_t>(be32(16), 1u << 30));
        h = int(std::min<uint32_t>(be32(20), 1u << 30));
        return true;
    }
    // JPEG: walk the marker segments to the first start-of-frame (ITU T.81 B.2).
    if (n >= 4 && is_jpeg(p, n)) {
        size_t i = 2;
        while (i + 9 < n) {
            if (p[i] != 0xFF) return false;
            const uint8_t marker = p[i + 1];
            if (marker == 0xFF) {  // fill byte
                ++i;
                continue;
            }
            if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
                i += 2;
                continue;
            }
            const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
            if (sof) {
                h = int(be16(i + 5));
                w = int(be16(i + 7));
                return true;
            }
            i += 2 + be16(i + 2);
        }
    }
    return false;
}

namespace {

/// PNG chunk lengths checked against the bytes present, up to IEND: stb_image grows its IDAT
/// buffer to a chunk's declared length before reading it, so one chunk claiming 2 GiB in a small
/// file would allocate 2 GiB (tests/data/fuzz-regressions/image/oom-png-idat-length-2gib.png).
/// Returns the reason for refusing, or an empty string.
std::string check_png_chunks(const uint8_t* p, size_t n) {
    size_t at = 8;  // after the signature
    while (at + 8 <= n) {
        const uint32_t length =
            (uint32_t(p[at]) << 24) | (uint32_t(p[at + 1]) << 16) | (uint32_t(p[at + 2]) << 8) | p[at + 3];
        const std::string type(reinterpret_cast<const char*>(p + at + 4), 4);
        if (uint64_t(length) + 12 > n - at)
            return fmt::format("truncated PNG: chunk '{}' at byte {} declares {} bytes, {} follow its header", type, at,
                               length, n - at - 8);
        if (type == "IEND") break;
        at += 12 + size_t(length);
    }
    return {};
}

bool is_png(const uint8_t* p, size_t n) { return n >= 8 && std::memcmp(p, "\x89PNG\r\n\x1a\n", 8) == 0; }

/// Warnings (corrupt data libjpeg recovers from) are not printed.
void jpeg_no_message(j_common_ptr, int) {}

/// A progressive file may declare any number of scans, each a pass over the whole image: more than
/// kMaxJpegScans is refused (as libjpeg-turbo's own fuzzers do), so a small file cannot keep the
/// decoder busy for minutes.
constexpr int kMaxJpegScans = 500;

void jpeg_scan_limit(j_common_ptr cinfo) {
    auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
    if (d->input_scan_number > kMaxJpegScans) {
        auto* e = reinterpret_cast<JpegErrors*>(cinfo->err);
        std::snprintf(e->message, sizeof e->message, "more than %d progressive scans", kMaxJpegScans);
        std::longjmp(e->jump, 1);
    }
}

/// Decodes a JPEG of `w` x `h` pixels (the size image_size_from_header read and checked) into
/// `level` as RGBA8 (alpha 255): baseline and progressive, grey, YCbCr/RGB and (Adobe) CMYK.
/// Returns false with the reason in `why` (a buffer of JMSG_LENGTH_MAX bytes).
bool decode_jpeg_rgba8(const uint8_t* bytes, size_t size, int w, int h, MipLevel& level, char* why) {
    // Nothing with a destructor lives in this frame between setjmp and the calls that may jump back
    // (`level` is the caller's).
    jpeg_decompress_struct cinfo;
    JpegErrors errors;  // src/core/jpeg_errors.h
    jpeg_progress_mgr progress;
    cinfo.err = jpeg_std_error(&errors.mgr);
    errors.mgr.error_exit = jpeg_error_exit;
    errors.mgr.emit_message = jpeg_no_message;
    errors.message[0] = '\0';
    if (setjmp(errors.jump)) {
        jpeg_destroy_decompress(&cinfo);
        std::snprintf(why, JMSG_LENGTH_MAX, "%s", errors.message);
        return false;
    }
    jpeg_create_decompress(&cinfo);
    progress.progress_monitor = jpeg_scan_limit;
    cinfo.progress = &progress;
    jpeg_mem_src(&cinfo, bytes, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    if (int(cinfo.image_width) != w || int(cinfo.image_height) != h) {
        std::snprintf(why, JMSG_LENGTH_MAX, "the frame header says %ux%u, its first one %dx%d", cinfo.image_width,
                      cinfo.image_height, w, h);
        jpeg_destroy_decompress(&cinfo);
        return false;
    }
    const bool cmyk = cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK;
    cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_EXT_RGBA;
    jpeg_start_decompress(&cinfo);
    level.width = w;
    level.height = h;
    level.texels.resize(size_t(w) * size_t(h) * 4);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = level.texels.data() + size_t(cinfo.output_scanline) * size_t(w) * 4;
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    if (cmyk) {
        // Adobe's CMYK JPEGs store inverted values: RGB = (255 - C)(255 - K) as stored, i.e. c * k / 255.
        for (size_t i = 0; i < level.texels.size(); i += 4) {
            uint8_t* t = &level.texels[i];
            const unsigned k = t[3];
            t[0] = uint8_t((t[0] * k + 127) / 255);
            t[1] = uint8_t((t[1] * k + 127) / 255);
            t[2] = uint8_t((t[2] * k + 127) / 255);
            t[3] = 255;
        }
    }
    return true;
}

}  // namespace

size_t decoded_image_bytes(int width, int height) {
    // Decoder output up to 16-bit RGBA (8 bytes), RGBA8 level (4) and its MIP chain (4/3 of it).
    const size_t texels = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
    return texels * (8 + 4 * 4 / 3 + 1);
}

std::string check_image_size(int w, int h, size_t max_memory) {
    if (w < 1 || h < 1) return fmt::format("the header declares an empty image ({}x{})", w, h);
    if (w > kMaxImageSide || h > kMaxImageSide)
        return fmt::format("the header declares {}x{} pixels, more than the {} per side whitted accepts", w, h,
                           kMaxImageSide);
    if (decoded_image_bytes(w, h) > max_memory)
        return fmt::format("the header declares {}x{} pixels: decoding needs about {} MiB, more than the limit of "
                           "{} MiB (--max-memory)",
                           w, h, decoded_image_bytes(w, h) >> 20, max_memory >> 20);
    return {};
}

MipLevel decode_image_rgba8(const uint8_t* bytes, size_t size, size_t max_memory, const FileLoc& loc,
                            const std::string& label) {
    if (bytes == nullptr || size == 0 || size > size_t(std::numeric_limits<int>::max()))
        throw Error(loc, fmt::format("image '{}' has no data", label));
    // Dimensions from the header first: stb_image allocates whatever the header claims.
    int header_w = 0, header_h = 0;
    if (!image_size_from_header(bytes, size, header_w, header_h))
        throw Error(loc, fmt::format("cannot decode image '{}': not a PNG, JPEG or WebP image (or its header is cut "
                                     "short): glTF core images are PNG or JPEG, EXT_texture_webp adds WebP",
                                     label));
    if (const std::string refused = check_image_size(header_w, header_h, max_memory); !refused.empty())
        throw Error(loc, fmt::format("image '{}' refused: {}", label, refused));
    if (is_webp(bytes, size)) {
        // RGBA8 straight from libwebp (lossy or lossless; alpha 255 where the file has none).
        MipLevel level;
        level.width = header_w;
        level.height = header_h;
        level.texels.resize(size_t(header_w) * size_t(header_h) * 4);
        if (!WebPDecodeRGBAInto(bytes, size, level.texels.data(), level.texels.size(), header_w * 4))
            throw Error(loc, fmt::format("cannot decode image '{}': corrupt WebP data", label));
        return level;
    }
    if (is_png(bytes, size))
        if (const std::string refused = check_png_chunks(bytes, size); !refused.empty())
            throw Error(loc, fmt::format("cannot decode image '{}': {}", label, refused));
    if (is_jpeg(bytes, size)) {
        MipLevel level;
        char why[JMSG_LENGTH_MAX];
        if (!decode_jpeg_rgba8(bytes, size, header_w, header_h, level, why))
            throw Error(loc, fmt::format("cannot decode image '{}': corrupt JPEG: {}", label, why));
        return level;
    }

    // Decode to RGBA, 16 bits per channel when the file has them.
    const int n = int(size);
    const bool sixteen = stbi_is_16_bit_from_memory(bytes, n) != 0;
    int w = 0, h = 0, channels = 0;
    void* pixels = sixteen ? static_cast<void*>(stbi_load_16_from_memory(bytes, n, &w, &h, &channels, 4))
                           : static_cast<void*>(stbi_load_from_memory(bytes, n, &w, &h, &channels, 4));
    if (pixels == nullptr || w < 1 || h < 1) {
        stbi_image_free(pixels);
        const char* why = stbi_failure_reason();
        throw Error(loc, fmt::format("cannot decode image '{}': {}", label, why != nullptr ? why : "unknown format"));
    }

    // RGBA8 texels; 16-bit channels rounded to 8 bits.
    MipLevel level;
    level.width = w;
    level.height = h;
    const size_t values = size_t(w) * size_t(h) * 4;
    level.texels.resize(values);
    if (sixteen) {
        const auto* v = static_cast<const uint16_t*>(pixels);
        for (size_t k = 0; k < values; ++k) level.texels[k] = uint8_t((uint32_t(v[k]) * 255u + 32767u) / 65535u);
    } else {
        std::memcpy(level.texels.data(), pixels, values);
    }
    stbi_image_free(pixels);
    return level;
}

}  // namespace whitted
