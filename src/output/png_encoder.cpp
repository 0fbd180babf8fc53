// PNG encoding with zlib, bands of rows in parallel (see png_encoder.h). Layout of the file:
// signature, IHDR, one tEXt/iTXt per text entry, one IDAT per band (the first starts with the
// zlib header, the last ends with the Adler-32 of the whole filtered stream), IEND.
#include "output/png_encoder.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include <tbb/parallel_for.h>
#include <zlib.h>

#include "core/error.h"

namespace whitted {

namespace {

constexpr size_t kDictionary = 32768;  ///< deflate's window: what a band may refer back to

void put32(std::vector<uint8_t>& out, uint32_t v) {
    const uint8_t b[4] = {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
    out.insert(out.end(), b, b + 4);
}

/// Appends one chunk: length, type, data, CRC-32 of type and data.
void put_chunk(std::vector<uint8_t>& out, const char (&type)[5], const uint8_t* data, size_t size) {
    if (size > 0x7fffffffu) throw Error("PNG chunk larger than 2^31 - 1 bytes");
    put32(out, uint32_t(size));
    const size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    if (size > 0) out.insert(out.end(), data, data + size);
    put32(out, uint32_t(crc32(0L, out.data() + start, uInt(4 + size))));
}

bool is_ascii(const std::string& s) {
    return std::all_of(s.begin(), s.end(), [](char c) { return (unsigned char)c < 0x80; });
}

/// tEXt for ASCII entries, iTXt (UTF-8) for anything else; keys cut to PNG's 79 bytes.
void put_text(std::vector<uint8_t>& out, std::string key, const std::string& value) {
    key.erase(std::remove(key.begin(), key.end(), '\0'), key.end());
    if (key.empty()) return;
    if (key.size() > 79) key.resize(79);
    std::vector<uint8_t> data(key.begin(), key.end());
    data.push_back(0);
    const bool latin = is_ascii(key) && is_ascii(value);
    if (!latin) data.insert(data.end(), {0, 0, 0, 0});  // uncompressed, no language, no translated key
    data.insert(data.end(), value.begin(), value.end());
    if (latin)
        put_chunk(out, "tEXt", data.data(), data.size());
    else
        put_chunk(out, "iTXt", data.data(), data.size());
}

uint8_t paeth(uint8_t a, uint8_t b, uint8_t c) {
    const int p = int(a) + int(b) - int(c);
    const int pa = std::abs(p - int(a)), pb = std::abs(p - int(b)), pc = std::abs(p - int(c));
    return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

/// Row filtered with `type` (PNG filter 0..4) into out[0 .. n); `prev` is the unfiltered row
/// above (all zero for the first row).
void filter_row(int type, const uint8_t* row, const uint8_t* prev, size_t n, size_t bpp, uint8_t* out) {
    switch (type) {
        case 0: std::memcpy(out, row, n); break;
        case 1:
            for (size_t i = 0; i < n; ++i) out[i] = uint8_t(row[i] - (i >= bpp ? row[i - bpp] : 0));
            break;
        case 2:
            for (size_t i = 0; i < n; ++i) out[i] = uint8_t(row[i] - prev[i]);
            break;
        case 3:
            for (size_t i = 0; i < n; ++i)
                out[i] = uint8_t(row[i] - ((int(i >= bpp ? row[i - bpp] : 0) + int(prev[i])) >> 1));
            break;
        default:
            for (size_t i = 0; i < n; ++i)
                out[i] = uint8_t(row[i] - paeth(i >= bpp ? row[i - bpp] : 0, prev[i], i >= bpp ? prev[i - bpp] : 0));
            break;
    }
}

/// The filter libpng's heuristic picks: the smallest sum of the filtered bytes read as signed.
size_t signed_sum(const uint8_t* v, size_t n) {
    size_t s = 0;
    for (size_t i = 0; i < n; ++i) s += size_t(std::abs(int(int8_t(v[i]))));
    return s;
}

/// Raw deflate of `data` primed with the `dict` bytes before it; ends on a byte boundary
/// (Z_SYNC_FLUSH) unless it is the last band (Z_FINISH).
std::vector<uint8_t> deflate_band(const uint8_t* data, size_t size, const uint8_t* dict, size_t dict_size, int level,
                                  bool last) {
    z_stream zs{};
    if (deflateInit2(&zs, level, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        throw Error(fmt::format("zlib: deflateInit2 failed (level {})", level));
    struct End {
        z_stream* zs;
        ~End() { deflateEnd(zs); }
    } end{&zs};
    if (dict_size > 0 && deflateSetDictionary(&zs, dict, uInt(dict_size)) != Z_OK)
        throw Error("zlib: deflateSetDictionary failed");
    std::vector<uint8_t> out(deflateBound(&zs, uLong(size)) + 64);
    zs.next_in = const_cast<Bytef*>(data);
    zs.avail_in = uInt(size);
    size_t written = 0;
    for (;;) {
        zs.next_out = out.data() + written;
        zs.avail_out = uInt(out.size() - written);
        const int rc = deflate(&zs, last ? Z_FINISH : Z_SYNC_FLUSH);
        written = out.size() - zs.avail_out;
        if (rc == Z_STREAM_END || (!last && rc == Z_OK && zs.avail_in == 0 && zs.avail_out > 0)) break;
        if (rc != Z_OK && rc != Z_BUF_ERROR) throw Error(fmt::format("zlib: deflate failed ({})", rc));
        out.resize(out.size() * 2);
    }
    out.resize(written);
    return out;
}

}  // namespace

std::vector<uint8_t> encode_png(std::span<const uint8_t> codes, int width, int height, int bits,
                                const std::vector<std::pair<std::string, std::string>>& text,
                                const PngOptions& options) {
    if (width <= 0 || height <= 0) throw Error(fmt::format("PNG: empty image {}x{}", width, height));
    if (bits != 8 && bits != 16) throw Error(fmt::format("PNG: unsupported bit depth {} (use 8 or 16)", bits));
    if (options.level < 0 || options.level > 9) throw Error(fmt::format("PNG: zlib level {} (use 0..9)", options.level));
    const size_t bpp = bits == 16 ? 6 : 3;  // bytes per pixel
    const size_t row_bytes = size_t(width) * bpp;
    if (codes.size() != row_bytes * size_t(height))
        throw Error(fmt::format("PNG: {} bytes of codes for a {}x{} {}-bit image", codes.size(), width, height, bits));

    // Bands: a function of the image alone, so the file never depends on the thread count.
    const size_t band_rows = options.band_rows > 0 ? size_t(options.band_rows)
                                                   : std::max<size_t>(1, (size_t(256) << 10) / row_bytes);
    const size_t bands = (size_t(height) + band_rows - 1) / band_rows;
    const size_t line = row_bytes + 1;  // filter byte + row
    std::vector<uint8_t> filtered(line * size_t(height));

    // Pass 1: filter every row (16-bit samples become big-endian first).
    tbb::parallel_for(size_t(0), bands, [&](size_t b) {
        std::vector<uint8_t> rows(2 * row_bytes), trial(row_bytes), best(row_bytes);
        const std::vector<uint8_t> zero(row_bytes, 0);
        const size_t y0 = b * band_rows, y1 = std::min(size_t(height), y0 + band_rows);
        auto raw_row = [&](size_t y, uint8_t* dst) -> const uint8_t* {
            const uint8_t* src = codes.data() + y * row_bytes;
            if (bits == 8) return src;
            for (size_t i = 0; i < row_bytes; i += 2) {
                uint16_t v;
                std::memcpy(&v, src + i, 2);
                dst[i] = uint8_t(v >> 8);
                dst[i + 1] = uint8_t(v & 0xff);
            }
            return dst;
        };
        const uint8_t* prev = y0 == 0 ? zero.data() : raw_row(y0 - 1, rows.data() + row_bytes);
        for (size_t y = y0; y < y1; ++y) {
            // Alternate halves of `rows`: the row above (16 bits: converted into the other half) stays intact.
            uint8_t* own = rows.data() + ((y - y0) % 2 == 0 ? 0 : row_bytes);
            const uint8_t* row = raw_row(y, own);
            uint8_t* out = filtered.data() + y * line;
            size_t best_sum = ~size_t(0);
            int best_type = 0;
            for (int type = 0; type <= 4; ++type) {
                filter_row(type, row, prev, row_bytes, bpp, trial.data());
                const size_t s = signed_sum(trial.data(), row_bytes);
                if (s < best_sum) {
                    best_sum = s;
                    best_type = type;
                    best.swap(trial);
                }
            }
            out[0] = uint8_t(best_type);
            std::memcpy(out + 1, best.data(), row_bytes);
            prev = row;
        }
    });

    // Pass 2: deflate every band, primed with the 32 KiB of filtered bytes before it.
    std::vector<std::vector<uint8_t>> compressed(bands);
    std::vector<uLong> adler(bands);
    tbb::parallel_for(size_t(0), bands, [&](size_t b) {
        const size_t start = b * band_rows * line;
        const size_t end = std::min(size_t(height), (b + 1) * band_rows) * line;
        const size_t dict = std::min(start, kDictionary);
        compressed[b] = deflate_band(filtered.data() + start, end - start, filtered.data() + start - dict, dict,
                                     options.level, b + 1 == bands);
        adler[b] = adler32(adler32(0L, nullptr, 0), filtered.data() + start, uInt(end - start));
    });
    uLong total_adler = adler[0];
    for (size_t b = 1; b < bands; ++b) {
        const size_t len = std::min(size_t(height), (b + 1) * band_rows) * line - b * band_rows * line;
        total_adler = adler32_combine(total_adler, adler[b], z_off_t(len));
    }

    // Assemble.
    std::vector<uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    size_t total = 64;
    for (const auto& c : compressed) total += c.size() + 12;
    for (const auto& [k, v] : text) total += k.size() + v.size() + 20;
    png.reserve(png.size() + total);
    std::vector<uint8_t> ihdr;
    put32(ihdr, uint32_t(width));
    put32(ihdr, uint32_t(height));
    ihdr.insert(ihdr.end(), {uint8_t(bits), 2 /* RGB */, 0, 0, 0 /* no interlace */});
    put_chunk(png, "IHDR", ihdr.data(), ihdr.size());
    for (const auto& [key, value] : text) put_text(png, key, value);
    // zlib header: deflate with a 32 KiB window, FLEVEL from the level, FCHECK making it % 31 == 0.
    const uint8_t cmf = 0x78;
    const int flevel = options.level <= 1 ? 0 : options.level <= 5 ? 1 : options.level == 6 ? 2 : 3;
    uint8_t flg = uint8_t(flevel << 6);
    flg = uint8_t(flg + (31 - (cmf * 256 + flg) % 31) % 31);
    compressed.front().insert(compressed.front().begin(), {cmf, flg});
    for (int shift = 24; shift >= 0; shift -= 8) compressed.back().push_back(uint8_t(total_adler >> shift));
    for (const auto& c : compressed) put_chunk(png, "IDAT", c.data(), c.size());
    put_chunk(png, "IEND", nullptr, 0);
    return png;
}

}  // namespace whitted
