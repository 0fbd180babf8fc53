// Helpers shared by the importer tests: asset paths, a scratch directory, and tiny writers for
// hand-made glTF files (base64 data URIs, uncompressed PNGs).
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "importers/scene_loader.h"
#include "core/error.h"

/// Each of v.x, v.y, v.z within eps of X, Y, Z (gtest EXPECT_NEAR each).
#define EXPECT_VEC3_NEAR(v, X, Y, Z, eps) \
    do {                                  \
        EXPECT_NEAR((v).x, (X), (eps));   \
        EXPECT_NEAR((v).y, (Y), (eps));   \
        EXPECT_NEAR((v).z, (Z), (eps));   \
    } while (0)

namespace whitted::test {

inline std::string asset(const std::string& relative) { return std::string(WHITTED_ASSETS_DIR) + "/gltf/" + relative; }
inline std::string invalid_file(const std::string& relative) {
    return std::string(WHITTED_TEST_DATA_DIR) + "/gltf-invalid/" + relative;
}

/// Options for tests that do not look at texels (decoding is most of the import time).
inline ImportOptions no_textures() {
    ImportOptions o;
    o.load_textures = false;
    return o;
}

/// The text of the error `fn` throws, or "" when it does not throw whitted::Error.
template <typename F>
std::string error_text(F&& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// A per-process scratch directory, removed when the test program ends.
inline const std::filesystem::path& scratch_dir() {
    static const struct Dir {
        std::filesystem::path path;
        Dir() {
            path = std::filesystem::temp_directory_path() / ("whitted_importer_test_" + std::to_string(::getpid()));
            std::filesystem::create_directories(path);
        }
        ~Dir() {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    } dir;
    return dir.path;
}

inline std::string write_file(const std::string& name, const std::string& text) {
    const std::filesystem::path p = scratch_dir() / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
}

inline std::string write_file(const std::string& name, const std::vector<uint8_t>& bytes) {
    const std::filesystem::path p = scratch_dir() / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return p.string();
}

/// A GLB file: `json` as its JSON chunk (padded with spaces to 4 bytes) and, when `bin` is not
/// empty, a BIN chunk (padded with zeros).
inline std::vector<uint8_t> make_glb(std::string json, std::vector<uint8_t> bin = {}) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin.push_back(0);
    std::vector<uint8_t> glb;
    auto u32 = [&](uint32_t v) {
        for (int i = 0; i < 4; ++i) glb.push_back(uint8_t(v >> (8 * i)));
    };
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
    u32(uint32_t(json.size()));
    u32(0x4E4F534A);  // "JSON"
    glb.insert(glb.end(), json.begin(), json.end());
    if (!bin.empty()) {
        u32(uint32_t(bin.size()));
        u32(0x004E4942);  // "BIN\0"
        glb.insert(glb.end(), bin.begin(), bin.end());
    }
    return glb;
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Little-endian byte buffer builder for hand-made buffers.
struct Bytes {
    std::vector<uint8_t> data;
    template <typename T>
    Bytes& put(std::initializer_list<T> values) {
        for (T v : values) {
            uint8_t b[sizeof(T)];
            std::memcpy(b, &v, sizeof(T));
            data.insert(data.end(), b, b + sizeof(T));
        }
        return *this;
    }
    Bytes& pad4() {
        while (data.size() % 4) data.push_back(0);
        return *this;
    }
    size_t size() const { return data.size(); }
};

inline std::string base64(const std::vector<uint8_t>& in) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t v = (uint32_t(in[i]) << 16) | (uint32_t(in[i + 1]) << 8) | in[i + 2];
        out += table[v >> 18], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += table[v & 63];
    }
    if (i + 1 == in.size()) {
        const uint32_t v = uint32_t(in[i]) << 16;
        out += table[v >> 18], out += table[(v >> 12) & 63], out += "==";
    } else if (i + 2 == in.size()) {
        const uint32_t v = (uint32_t(in[i]) << 16) | (uint32_t(in[i + 1]) << 8);
        out += table[v >> 18], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += '=';
    }
    return out;
}

inline std::string data_uri(const std::vector<uint8_t>& bytes, const char* mime = "application/octet-stream") {
    return std::string("data:") + mime + ";base64," + base64(bytes);
}

/// An uncompressed PNG (zlib "stored" blocks). `rows` holds height rows of raw samples, big-endian
/// for 16-bit depth. color_type: 0 gray, 2 RGB, 4 gray+alpha, 6 RGBA.
inline std::vector<uint8_t> make_png(int width, int height, int bit_depth, int color_type,
                                     const std::vector<uint8_t>& rows) {
    auto crc32 = [](const uint8_t* p, size_t n) {
        uint32_t c = 0xFFFFFFFFu;
        for (size_t i = 0; i < n; ++i) {
            c ^= p[i];
            for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        }
        return c ^ 0xFFFFFFFFu;
    };
    auto be32 = [](std::vector<uint8_t>& v, uint32_t x) {
        for (int s = 24; s >= 0; s -= 8) v.push_back(uint8_t(x >> s));
    };
    std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    auto chunk = [&](const char* type, const std::vector<uint8_t>& body) {
        be32(png, uint32_t(body.size()));
        std::vector<uint8_t> tb(type, type + 4);
        tb.insert(tb.end(), body.begin(), body.end());
        png.insert(png.end(), tb.begin(), tb.end());
        be32(png, crc32(tb.data(), tb.size()));
    };
    std::vector<uint8_t> ihdr;
    be32(ihdr, uint32_t(width));
    be32(ihdr, uint32_t(height));
    ihdr.insert(ihdr.end(), {uint8_t(bit_depth), uint8_t(color_type), 0, 0, 0});
    chunk("IHDR", ihdr);
    // Scanlines with filter byte 0, in one stored deflate block (images here are tiny).
    const size_t row_bytes = rows.size() / size_t(height);
    std::vector<uint8_t> raw;
    for (int y = 0; y < height; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), rows.begin() + long(size_t(y) * row_bytes),
                   rows.begin() + long(size_t(y + 1) * row_bytes));
    }
    std::vector<uint8_t> z = {0x78,
                              0x01,
                              0x01,
                              uint8_t(raw.size()),
                              uint8_t(raw.size() >> 8),
                              uint8_t(~raw.size()),
                              uint8_t(~raw.size() >> 8)};
    z.insert(z.end(), raw.begin(), raw.end());
    uint32_t a = 1, b = 0;
    for (uint8_t c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
    be32(z, (b << 16) | a);
    chunk("IDAT", z);
    chunk("IEND", {});
    return png;
}

}  // namespace whitted::test
