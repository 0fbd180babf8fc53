// Texture lookups: wrap modes, filtering, sRGB decoding, MIP chains, KHR_texture_transform.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "shading/texture_sampling.h"

namespace whitted {
namespace {

constexpr float kEps = 1e-6f;
constexpr float kHalfPi = 1.57079632679f;

/// A w x h texture whose red channel holds `red` (row-major), green/blue 0, alpha 255.
Texture red_texture(int w, int h, const std::vector<uint8_t>& red, FilterMode filter, WrapMode wrap) {
    Texture t;
    MipLevel level;
    level.width = w;
    level.height = h;
    for (uint8_t r : red) level.texels.insert(level.texels.end(), {r, 0, 0, 255});
    t.levels.push_back(std::move(level));
    t.mag_filter = t.min_filter = filter;
    t.wrap_s = t.wrap_t = wrap;
    t.use_mips = false;
    return t;
}

/// A w x h RGBA texture with every texel set to `rgba`.
Texture uniform_texture(int w, int h, std::array<uint8_t, 4> rgba, bool srgb) {
    Texture t;
    MipLevel level;
    level.width = w;
    level.height = h;
    for (int i = 0; i < w * h; ++i) level.texels.insert(level.texels.end(), rgba.begin(), rgba.end());
    t.levels.push_back(std::move(level));
    t.srgb = srgb;
    return t;
}

float red_at(const Texture& t, float u, float v = 0.5f, float lod = 0.f) { return sample_texture(t, {u, v}, lod).x; }
float unorm(int v) { return float(v) / 255.f; }

// ---- transfer functions ----------------------------------------------------------------------

TEST(TextureSampling, SrgbDecode) {
    EXPECT_EQ(srgb8_to_linear(0), 0.f);
    EXPECT_EQ(srgb8_to_linear(255), 1.f);
    EXPECT_NEAR(srgb8_to_linear(128), 0.2158605f, 1e-6f);
    EXPECT_NEAR(srgb8_to_linear(10), 10.f / 255.f / 12.92f, 1e-7f);  // linear segment
    for (int i = 1; i < 256; ++i) EXPECT_GT(srgb8_to_linear(uint8_t(i)), srgb8_to_linear(uint8_t(i - 1)));
}

TEST(TextureSampling, SrgbEncodeRoundTrips) {
    for (int i = 0; i < 256; ++i) EXPECT_EQ(linear_to_srgb8(srgb8_to_linear(uint8_t(i))), i) << i;
    EXPECT_EQ(linear_to_srgb8(0.5f), 188);
    EXPECT_EQ(linear_to_srgb8(-1.f), 0);
    EXPECT_EQ(linear_to_srgb8(7.f), 255);
    EXPECT_EQ(linear_to_srgb8(std::nanf("")), 0);
}

// The threshold lookup gives the formula's codes: a sweep of every 61st float from 0 to 1 (17.5
// million values), every float within 4096 ulps of each point where the sweep sees the code
// change (found again here by bisection between the two sweep points), and the ends.
TEST(TextureSampling, SrgbEncodeTableIsTheFormula) {
    auto same = [](uint32_t bits) {
        const float v = std::bit_cast<float>(bits);
        return linear_to_srgb8(v) == linear_to_srgb8_formula(v);
    };
    const uint32_t one = std::bit_cast<uint32_t>(1.f);
    int changes = 0;
    uint32_t prev = 0;
    uint8_t prev_code = 0;
    for (uint32_t bits = 61; bits <= one; bits += 61) {
        ASSERT_TRUE(same(bits)) << std::bit_cast<float>(bits);
        const uint8_t code = linear_to_srgb8_formula(std::bit_cast<float>(bits));
        if (code != prev_code) {
            uint32_t lo = prev, hi = bits;  // code(lo) < code(hi): the first change lies in (lo, hi]
            while (hi - lo > 1) {
                const uint32_t mid = lo + (hi - lo) / 2;
                (linear_to_srgb8_formula(std::bit_cast<float>(mid)) != prev_code ? hi : lo) = mid;
            }
            for (uint32_t b = hi - std::min(hi, 4096u); b < hi + 4096u; ++b) ASSERT_TRUE(same(b)) << std::bit_cast<float>(b);
            ++changes;
        }
        prev = bits;
        prev_code = code;
    }
    EXPECT_EQ(changes, 255);  // every code from 1 to 255 begins somewhere in (0, 1]
    for (float v : {0.f, -0.f, 1e-45f, 1.f, std::nextafter(1.f, 0.f), 2.f, -1.f, std::nanf(""),
                    std::numeric_limits<float>::infinity()})
        EXPECT_EQ(linear_to_srgb8(v), linear_to_srgb8_formula(v)) << v;
}

// ---- wrap modes (nearest, exact texel values) ------------------------------------------------

TEST(TextureSampling, NearestHitsTexelCentres) {
    const Texture t = red_texture(4, 1, {10, 20, 30, 40}, FilterMode::Nearest, WrapMode::Repeat);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(red_at(t, (float(i) + 0.5f) / 4.f), unorm(10 * (i + 1)));
}

TEST(TextureSampling, WrapRepeat) {
    const Texture t = red_texture(4, 1, {10, 20, 30, 40}, FilterMode::Nearest, WrapMode::Repeat);
    EXPECT_EQ(red_at(t, 1.125f), unorm(10));
    EXPECT_EQ(red_at(t, 1.f), unorm(10));
    EXPECT_EQ(red_at(t, -0.125f), unorm(40));
    EXPECT_EQ(red_at(t, -1.875f), unorm(10));
    EXPECT_EQ(red_at(t, 7.625f), unorm(30));
    EXPECT_EQ(red_at(t, -1e-9f), unorm(40));  // u - floor(u) rounds to 1.0f: must stay in the last texel
}

TEST(TextureSampling, WrapClampToEdge) {
    const Texture t = red_texture(4, 1, {10, 20, 30, 40}, FilterMode::Nearest, WrapMode::ClampToEdge);
    EXPECT_EQ(red_at(t, 1.5f), unorm(40));
    EXPECT_EQ(red_at(t, 1.f), unorm(40));
    EXPECT_EQ(red_at(t, -3.f), unorm(10));
    EXPECT_EQ(red_at(t, 0.f), unorm(10));
}

TEST(TextureSampling, WrapMirroredRepeat) {
    const Texture t = red_texture(4, 1, {10, 20, 30, 40}, FilterMode::Nearest, WrapMode::MirroredRepeat);
    EXPECT_EQ(red_at(t, 0.125f), unorm(10));
    EXPECT_EQ(red_at(t, 1.125f), unorm(40));   // first mirrored period runs backwards
    EXPECT_EQ(red_at(t, 1.375f), unorm(30));
    EXPECT_EQ(red_at(t, 1.875f), unorm(10));
    EXPECT_EQ(red_at(t, 2.125f), unorm(10));   // period 2
    EXPECT_EQ(red_at(t, -0.125f), unorm(10));  // mirrored across 0
    EXPECT_EQ(red_at(t, -0.625f), unorm(30));
    EXPECT_EQ(red_at(t, -1.125f), unorm(40));
}

TEST(TextureSampling, WrapModesPerAxis) {
    // 2x2: row 0 = (10, 20), row 1 = (30, 40). s repeats, t clamps.
    Texture t = red_texture(2, 2, {10, 20, 30, 40}, FilterMode::Nearest, WrapMode::Repeat);
    t.wrap_t = WrapMode::ClampToEdge;
    EXPECT_EQ(red_at(t, 1.25f, 0.25f), unorm(10));
    EXPECT_EQ(red_at(t, 0.25f, 1.25f), unorm(30));   // clamped to the last row
    EXPECT_EQ(red_at(t, 1.75f, -5.f), unorm(20));    // clamped to the first row, repeated column
}

TEST(TextureSampling, HugeAndNonFiniteUv) {
    for (WrapMode mode : {WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::MirroredRepeat}) {
        for (FilterMode filter : {FilterMode::Nearest, FilterMode::Linear}) {
            const Texture t = red_texture(4, 1, {10, 20, 30, 40}, filter, mode);
            const float at_zero = red_at(t, 0.f, 0.f);
            EXPECT_EQ(red_at(t, std::nanf(""), 0.f), at_zero);
            EXPECT_EQ(red_at(t, 0.f, std::nanf("")), at_zero);
            EXPECT_EQ(red_at(t, kInfinity, 0.f), at_zero);
            EXPECT_EQ(red_at(t, -kInfinity, 0.f), at_zero);
            for (float u : {1e20f, -1e20f, 3e38f, -3e38f, 16777217.f}) {
                const Vec4f c = sample_texture(t, {u, u});
                EXPECT_TRUE(std::isfinite(c.x) && c.x >= unorm(10) - kEps && c.x <= unorm(40) + kEps);
            }
            EXPECT_EQ(red_at(t, 0.3f, 0.3f, std::nanf("")), red_at(t, 0.3f, 0.3f, 0.f));
        }
    }
}

// ---- filtering -------------------------------------------------------------------------------

TEST(TextureSampling, BilinearMidpoint) {
    const Texture t = red_texture(2, 1, {0, 200}, FilterMode::Linear, WrapMode::ClampToEdge);
    EXPECT_NEAR(red_at(t, 0.5f), unorm(100), kEps);   // half way between the centres 0.25 and 0.75
    EXPECT_NEAR(red_at(t, 0.375f), unorm(50), kEps);
    EXPECT_NEAR(red_at(t, 0.25f), 0.f, kEps);         // exactly on a centre
    EXPECT_NEAR(red_at(t, 0.f), 0.f, kEps);           // clamped edge
    EXPECT_NEAR(red_at(t, 1.f), unorm(200), kEps);

    // Repeat blends across the seam: u = 0 lies between the last and the first texel.
    const Texture r = red_texture(2, 1, {0, 200}, FilterMode::Linear, WrapMode::Repeat);
    EXPECT_NEAR(red_at(r, 0.f), unorm(100), kEps);
    EXPECT_NEAR(red_at(r, 1.f), unorm(100), kEps);
}

TEST(TextureSampling, SrgbDecodedBeforeFiltering) {
    // Black and white sRGB texels: the filtered midpoint is linear 0.5, not decode(128).
    Texture t = red_texture(2, 1, {0, 255}, FilterMode::Linear, WrapMode::ClampToEdge);
    t.srgb = true;
    EXPECT_NEAR(red_at(t, 0.5f), 0.5f, kEps);
}

TEST(TextureSampling, SrgbTexelsAndLinearAlpha) {
    const Texture s = uniform_texture(1, 1, {128, 128, 128, 128}, true);
    const Vec4f c = sample_texture(s, {0.5f, 0.5f});
    EXPECT_NEAR(c.x, 0.2158605f, 1e-6f);
    EXPECT_NEAR(c.y, 0.2158605f, 1e-6f);
    EXPECT_NEAR(c.z, 0.2158605f, 1e-6f);
    EXPECT_NEAR(c.w, 128.f / 255.f, 1e-6f);  // alpha is never sRGB-decoded

    const Texture l = uniform_texture(1, 1, {128, 128, 128, 128}, false);
    const Vec4f d = sample_texture(l, {0.5f, 0.5f});
    EXPECT_NEAR(d.x, 128.f / 255.f, 1e-6f);
    EXPECT_NEAR(d.w, 128.f / 255.f, 1e-6f);
}

TEST(TextureSampling, EmptyTextureIsWhite) {
    const Texture t;
    EXPECT_EQ(sample_texture(t, {0.3f, 0.7f}), Vec4f(1.f, 1.f, 1.f, 1.f));
    EXPECT_EQ(sample_texture(t, {0.3f, 0.7f}, 3.f), Vec4f(1.f, 1.f, 1.f, 1.f));
}

TEST(TextureSampling, MagAndMinFilters) {
    // mag = Nearest, min = Linear: lod <= 0 picks the texel, lod > 0 without mips blends level 0.
    Texture t = red_texture(2, 1, {0, 200}, FilterMode::Nearest, WrapMode::ClampToEdge);
    t.min_filter = FilterMode::Linear;
    EXPECT_EQ(red_at(t, 0.4f, 0.5f, 0.f), 0.f);
    EXPECT_EQ(red_at(t, 0.4f, 0.5f, -2.f), 0.f);
    EXPECT_NEAR(red_at(t, 0.4f, 0.5f, 1.f), unorm(60), kEps);
}

TEST(TextureSampling, TrilinearBetweenLevels) {
    Texture t = red_texture(2, 2, {200, 200, 200, 200}, FilterMode::Linear, WrapMode::Repeat);
    MipLevel coarse;
    coarse.width = coarse.height = 1;
    coarse.texels = {100, 0, 0, 255};
    t.levels.push_back(coarse);
    t.use_mips = true;
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 0.f), unorm(200), kEps);
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 0.5f), unorm(150), 1e-5f);
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 0.25f), unorm(175), 1e-5f);
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 1.f), unorm(100), kEps);
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 9.f), unorm(100), kEps);  // clamped to the coarsest level
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, kInfinity), unorm(100), kEps);
    t.use_mips = false;
    EXPECT_NEAR(red_at(t, 0.3f, 0.6f, 1.f), unorm(200), kEps);
}

// ---- MIP chains ------------------------------------------------------------------------------

TEST(TextureSampling, MipChainSizes) {
    auto sizes = [](int w, int h) {
        Texture t = uniform_texture(w, h, {1, 2, 3, 4}, false);
        build_mip_levels(t);
        std::vector<std::pair<int, int>> s;
        for (const MipLevel& l : t.levels) {
            EXPECT_EQ(l.texels.size(), size_t(l.width) * size_t(l.height) * 4);
            s.emplace_back(l.width, l.height);
        }
        return s;
    };
    using Sizes = std::vector<std::pair<int, int>>;
    EXPECT_EQ(sizes(5, 3), (Sizes{{5, 3}, {2, 1}, {1, 1}}));
    EXPECT_EQ(sizes(4, 4), (Sizes{{4, 4}, {2, 2}, {1, 1}}));
    EXPECT_EQ(sizes(1, 8), (Sizes{{1, 8}, {1, 4}, {1, 2}, {1, 1}}));
    EXPECT_EQ(sizes(1, 1), (Sizes{{1, 1}}));
    EXPECT_EQ(sizes(7, 2), (Sizes{{7, 2}, {3, 1}, {1, 1}}));
}

TEST(TextureSampling, MipOfUniformTextureIsUniform) {
    Texture t = uniform_texture(5, 3, {37, 128, 250, 77}, true);
    build_mip_levels(t);
    for (size_t l = 1; l < t.levels.size(); ++l)
        for (size_t i = 0; i < t.levels[l].texels.size(); i += 4) {
            EXPECT_EQ(t.levels[l].texels[i + 0], 37);
            EXPECT_EQ(t.levels[l].texels[i + 1], 128);
            EXPECT_EQ(t.levels[l].texels[i + 2], 250);
            EXPECT_EQ(t.levels[l].texels[i + 3], 77);
        }
}

TEST(TextureSampling, MipOfCheckerboardAveragesInLinearSpace) {
    // 4x4 sRGB checkerboard of black and white, alpha 255: linear mean 0.5 -> sRGB 188.
    Texture t;
    MipLevel base;
    base.width = base.height = 4;
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const uint8_t v = ((x + y) & 1) ? 255 : 0;
            base.texels.insert(base.texels.end(), {v, v, v, 255});
        }
    t.levels.push_back(base);
    t.srgb = true;
    build_mip_levels(t);
    ASSERT_EQ(t.levels.size(), 3u);
    for (size_t l = 1; l < 3; ++l)
        for (size_t i = 0; i < t.levels[l].texels.size(); i += 4) {
            EXPECT_EQ(t.levels[l].texels[i], 188);
            EXPECT_EQ(t.levels[l].texels[i + 3], 255);
        }

    // The same texels as linear data average to 127.5 -> 128.
    t.srgb = false;
    build_mip_levels(t);
    EXPECT_EQ(t.levels[1].texels[0], 128);
}

TEST(TextureSampling, MipOddSizesKeepEveryTexel) {
    // 3 -> 1: equal thirds.
    Texture three = red_texture(3, 1, {0, 90, 180}, FilterMode::Linear, WrapMode::Repeat);
    build_mip_levels(three);
    ASSERT_EQ(three.levels.size(), 2u);
    EXPECT_EQ(three.levels[1].texels[0], 90);

    // 5 -> 2: weights (1, 1, 1/2) and (1/2, 1, 1) over 2.5 texels.
    Texture five = red_texture(5, 1, {0, 0, 100, 200, 200}, FilterMode::Linear, WrapMode::Repeat);
    build_mip_levels(five);
    ASSERT_EQ(five.levels[1].width, 2);
    EXPECT_EQ(five.levels[1].texels[0], 20);   // (0 + 0 + 50) / 2.5
    EXPECT_EQ(five.levels[1].texels[4], 180);  // (50 + 200 + 200) / 2.5
    EXPECT_EQ(five.levels[2].texels[0], 100);  // mean of the unquantised level 1: (20 + 180) / 2
}

TEST(TextureSampling, MipBuildIsDeterministicAndReplacesLevels) {
    Texture t = red_texture(13, 7, std::vector<uint8_t>(91, 0), FilterMode::Linear, WrapMode::Repeat);
    for (size_t i = 0; i < t.levels[0].texels.size(); ++i) t.levels[0].texels[i] = uint8_t((i * 2654435761u) >> 7);
    t.srgb = true;
    build_mip_levels(t);
    const std::vector<MipLevel> first = t.levels;
    build_mip_levels(t);  // rebuilding replaces, never appends
    ASSERT_EQ(t.levels.size(), first.size());
    for (size_t l = 0; l < first.size(); ++l) EXPECT_EQ(t.levels[l].texels, first[l].texels);
}

// ---- KHR_texture_transform -------------------------------------------------------------------

TEST(TextureTransform, IdentityLeavesUv) {
    const TextureTransform xf;
    EXPECT_EQ(apply_texture_transform(xf, {0.3f, -2.f}), Vec2f(0.3f, -2.f));
}

TEST(TextureTransform, RotationMatchesSpec) {
    // R = [cos sin; -sin cos]: 90 degrees turns (1, 0) into (0, -1), i.e. counter-clockwise
    // in glTF's UV space where v points down (the extension's "rotate the UVs counter-clockwise").
    TextureTransform xf;
    xf.rotation = kHalfPi;
    const Vec2f r = apply_texture_transform(xf, {1.f, 0.f});
    EXPECT_NEAR(r.x, 0.f, 1e-6f);
    EXPECT_NEAR(r.y, -1.f, 1e-6f);
    const Vec2f q = apply_texture_transform(xf, {0.f, 1.f});
    EXPECT_NEAR(q.x, 1.f, 1e-6f);
    EXPECT_NEAR(q.y, 0.f, 1e-6f);
}

TEST(TextureTransform, SpecExampleSelectsLowerLeftQuadrant) {
    // The extension's example: offset (0, 1), rotation pi/2, scale 0.5 "utilizes only the lower
    // left quadrant of the source image, rotated clockwise 90 degrees".
    TextureTransform xf;
    xf.offset = {0.f, 1.f};
    xf.rotation = kHalfPi;
    xf.scale = {0.5f, 0.5f};
    const Vec2f corners[4][2] = {{{0, 0}, {0, 1}}, {{1, 0}, {0, 0.5f}}, {{0, 1}, {0.5f, 1}}, {{1, 1}, {0.5f, 0.5f}}};
    for (const auto& [in, expected] : corners) {
        const Vec2f out = apply_texture_transform(xf, in);
        EXPECT_NEAR(out.x, expected.x, 1e-6f);
        EXPECT_NEAR(out.y, expected.y, 1e-6f);
    }
}

TEST(TextureTransform, OrderIsTranslateRotateScale) {
    TextureTransform xf;
    xf.offset = {0.5f, 0.f};
    xf.scale = {2.f, 2.f};
    const Vec2f a = apply_texture_transform(xf, {1.f, 1.f});  // scale first, then offset
    EXPECT_NEAR(a.x, 2.5f, 1e-6f);
    EXPECT_NEAR(a.y, 2.f, 1e-6f);

    // Anisotropic scale happens before the rotation: (1, 0) -> (2, 0) -> (0, -2).
    TextureTransform r;
    r.scale = {2.f, 1.f};
    r.rotation = kHalfPi;
    const Vec2f b = apply_texture_transform(r, {1.f, 0.f});
    EXPECT_NEAR(b.x, 0.f, 1e-6f);
    EXPECT_NEAR(b.y, -2.f, 1e-6f);
}

// ---- procedural checker (scene files) ----


Checker red_yellow(bool world) {
    Checker c;
    c.color_a = {1.f, 0.f, 0.f};
    c.color_b = {1.f, 1.f, 0.f};
    c.size = 0.5f;
    c.world_space = world;
    return c;
}

TEST(Checker, UvPointSamplesAlternate) {
    const Checker c = red_yellow(false);
    EXPECT_EQ(sample_checker(c, {0.1f, 0.1f}, {}, {}), c.color_a);   // cell (0, 0)
    EXPECT_EQ(sample_checker(c, {0.6f, 0.1f}, {}, {}), c.color_b);   // cell (1, 0)
    EXPECT_EQ(sample_checker(c, {0.6f, 0.6f}, {}, {}), c.color_a);   // cell (1, 1)
    EXPECT_EQ(sample_checker(c, {-0.1f, 0.1f}, {}, {}), c.color_b);  // cell (-1, 0)
    EXPECT_EQ(sample_checker(c, {-0.1f, -0.1f}, {}, {}), c.color_a); // cell (-1, -1)
}

TEST(Checker, UvPointSampleParityFarFromTheOrigin) {
    // The unfiltered parity test (floor(x) even or odd) at cell indices that need all of a float's
    // bits, on both sides of zero, and beyond 2^53, where every double is an even integer.
    const Checker c = red_yellow(false);
    for (const int64_t k : {int64_t(2097151), int64_t(2097150), int64_t(-2097151), int64_t(-2097152)}) {
        const Vec2f uv{(float(k) + 0.5f) * c.size, 0.25f * c.size};  // exact in float; v in cell 0
        EXPECT_EQ(sample_checker(c, uv, {}, {}), k % 2 == 0 ? c.color_a : c.color_b) << k;
    }
    EXPECT_EQ(sample_checker(c, {3e30f, 0.25f * c.size}, {}, {}), c.color_a);
    EXPECT_EQ(sample_checker(c, {-3e30f, 0.25f * c.size}, {}, {}), c.color_a);
}

TEST(Checker, WorldSpaceFloorOnCellBoundaryDoesNotFlicker) {
    // A floor at y = 0 lies exactly on a cell boundary of the 3D checker; every point of it must
    // pick the same y cell, so the pattern is a clean 2D checkerboard in x and z.
    const Checker c = red_yellow(true);
    const Vec3f up{0.f, 1.f, 0.f};
    for (float y : {0.f, -0.f, 1e-9f, -1e-9f}) {
        EXPECT_EQ(sample_checker(c, {}, {0.1f, y, 0.1f}, up), sample_checker(c, {}, {0.1f, 0.f, 0.1f}, up));
        EXPECT_NE(sample_checker(c, {}, {0.6f, y, 0.1f}, up), sample_checker(c, {}, {0.1f, y, 0.1f}, up));
        EXPECT_EQ(sample_checker(c, {}, {0.6f, y, 0.6f}, up), sample_checker(c, {}, {0.1f, y, 0.1f}, up));
    }
}

TEST(Checker, WorldSpaceFloorFarFromTheOriginDoesNotFlicker) {
    // At x = 1e3 a float hit point on the floor y = 0 may be off the plane by a few ulps of 1e3
    // (about 1e-4), more than a step of 1e-4 * size = 5e-5: the step must scale with |p|.
    const Checker c = red_yellow(true);
    const Vec3f up{0.f, 1.f, 0.f};
    const float ulp = 1000.f * std::numeric_limits<float>::epsilon();
    for (float dy : {0.f, 3.f * ulp, -3.f * ulp})
        EXPECT_EQ(sample_checker(c, {}, {1000.1f, dy, 2000.1f}, up), sample_checker(c, {}, {1000.1f, 0.f, 2000.1f}, up))
            << dy;
}

TEST(Checker, BoxFilterMatchesNumericalAverage) {
    // The closed-form filtered checker equals the average of point samples over the footprint
    // square [u - w/2, u + w/2] x [v - w/2, v + w/2].
    const Checker c = red_yellow(false);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(-3.f, 3.f), width(0.01f, 0.9f);
    for (int trial = 0; trial < 100; ++trial) {
        const Vec2f uv{pos(rng), pos(rng)};
        const float w = width(rng);
        const int n = 400;
        double green = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const Vec2f q{uv.x + w * ((i + 0.5f) / n - 0.5f), uv.y + w * ((j + 0.5f) / n - 0.5f)};
                green += sample_checker(c, q, {}, {}).y;
            }
        green /= double(n) * n;
        EXPECT_NEAR(sample_checker(c, uv, {}, {}, w).y, green, 5e-3) << "uv " << uv.x << "," << uv.y << " w " << w;
    }
}

TEST(Checker, WideFootprintGivesTheMean) {
    const Checker c = red_yellow(false);
    const Color mean = (c.color_a + c.color_b) * 0.5f;
    EXPECT_EQ(sample_checker(c, {0.3f, 0.2f}, {}, {}, 5.f), mean);
    // World space on a floor: the footprint lies in x and z, not across the y boundary.
    const Checker w = red_yellow(true);
    const Color far = sample_checker(w, {}, {0.3f, 0.f, 0.2f}, {0.f, 1.f, 0.f}, 5.f);
    EXPECT_NEAR(far.y, mean.y, 1e-6f);
}

TEST(Checker, NonFiniteInputsGiveAFiniteColor) {
    const Checker c = red_yellow(false);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(sample_checker(c, {nan, 0.f}, {}, {}), c.color_a);
    EXPECT_EQ(sample_checker(c, {0.1f, 0.1f}, {}, {}, nan), c.color_a);
    const Checker w = red_yellow(true);
    EXPECT_EQ(sample_checker(w, {}, {kInfinity, 0.f, 0.f}, {0.f, 1.f, 0.f}), w.color_a);
}

}  // namespace
}  // namespace whitted
