// CodeTable: display codes by thresholds equal the transform's own codes, and transforms that are
// not per-channel non-decreasing are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "output/code_table.h"
#include "output/image_output.h"

namespace whitted {
namespace {

/// Codes of `f` for one sanitised value per channel, evaluated directly.
uint32_t direct_code(const CodeTable::Evaluate& f, int c, float x, int bits) {
    float rgb[3] = {0.f, 0.f, 0.f};
    rgb[c] = x;
    f(rgb, 1);
    return display_code(rgb[c], bits == 16 ? 65535.f : 255.f);
}

/// Every value we compare at: all floats near each code boundary of the input, a dense sweep of
/// [-2, 2] and random floats over the whole sanitised range.
std::vector<float> inputs(uint32_t seed) {
    std::vector<float> v;
    for (float x = -2.f; x <= 2.f; x += 1.f / 4096.f) v.push_back(x);
    for (float x : {0.f, -0.f, 1.f, kDisplayInputLimit, -kDisplayInputLimit, 1e-30f, -1e-30f, 0.0031308f})
        for (int o = -64; o <= 64; ++o) v.push_back(CodeTable::from_key(uint32_t(int64_t(CodeTable::key(x)) + o)));
    std::mt19937 rng(seed);
    std::uniform_int_distribution<uint32_t> any;
    while (v.size() < 2'000'000) {
        float x;
        const uint32_t u = any(rng);
        std::memcpy(&x, &u, 4);
        v.push_back(sanitise_linear(x));
    }
    for (float& x : v) x = sanitise_linear(x);
    return v;
}

TEST(CodeTable, KeysKeepTheOrderOfFloats) {
    const std::vector<float> xs{-kDisplayInputLimit, -1.f, -1e-30f, -0.f, 0.f, 1e-30f, 0.5f, 1.f, kDisplayInputLimit};
    for (size_t i = 1; i < xs.size(); ++i) {
        EXPECT_LT(CodeTable::key(xs[i - 1]), CodeTable::key(xs[i])) << xs[i - 1] << " " << xs[i];
        EXPECT_EQ(CodeTable::from_key(CodeTable::key(xs[i])), xs[i]);
    }
}

TEST(CodeTable, StandardViewCodesEqualTheTransformsAt8And16Bits) {
    const DisplayTransform t(ColorSettings{});  // the bundled config's Standard view: the sRGB curve
    const CodeTable::Evaluate f = [&](float* rgb, size_t n) { t.apply(rgb, n); };
    EXPECT_NE(t.code_table(8), nullptr) << "the Standard view is per-channel and non-decreasing";
    EXPECT_EQ(t.code_table(16), nullptr) << "16-bit codes come from the transform (a table costs more than it saves)";
    for (int bits : {8, 16}) {
        const std::optional<CodeTable> built = CodeTable::build(f, bits);
        ASSERT_TRUE(built) << bits << " bits";
        const CodeTable* table = &*built;
        size_t differ = 0, checked = 0;
        const std::vector<float> xs = inputs(uint32_t(bits));
        std::vector<float> rgb(3 * xs.size());
        for (size_t i = 0; i < xs.size(); ++i) rgb[3 * i] = xs[i], rgb[3 * i + 1] = xs[(i * 7) % xs.size()], rgb[3 * i + 2] = xs[(i * 13) % xs.size()];
        std::vector<float> out = rgb;
        t.apply(out.data(), xs.size());
        for (size_t i = 0; i < 3 * xs.size(); ++i, ++checked)
            differ += table->code(int(i % 3), rgb[i]) != display_code(out[i], bits == 16 ? 65535.f : 255.f);
        EXPECT_EQ(differ, 0u) << "of " << checked << " channel values at " << bits << " bits";
        // Every code is reached: 0 below the toe, the maximum at and above 1.
        EXPECT_EQ(table->code(0, 0.f), 0u);
        EXPECT_EQ(table->code(1, 1.f), bits == 16 ? 65535u : 255u);
        EXPECT_EQ(table->code(2, -1.f), 0u);
    }
}

TEST(CodeTable, DisplayCodesAreTheSameThroughTheTableAndTheTransform) {
    // display_codes takes the table for the Standard view and the transform for ACES (which mixes
    // channels); both agree with apply() + display_code pixel by pixel.
    for (const char* view : {"Standard", "ACES 1.0 SDR-video", "Raw"}) {
        ColorSettings cs;
        cs.view = view;
        const DisplayTransform t(cs);
        std::vector<Color> px;
        for (int i = 0; i < 70000; ++i)
            px.push_back(Color(float(i % 1013) / 400.f - 0.2f, float(i % 577) / 900.f, i % 5 == 0 ? NAN : float(i % 91) * 1e3f));
        px.push_back(Color(INFINITY, -INFINITY, NAN));
        for (int bits : {8, 16}) {
            std::vector<uint8_t> codes(px.size() * 3 * size_t(bits / 8));
            display_codes(px, t, bits, codes);
            size_t differ = 0;
            for (size_t i = 0; i < px.size(); ++i) {
                float rgb[3];
                for (int c = 0; c < 3; ++c) rgb[c] = sanitise_linear(px[i][c]);
                t.apply(rgb, 1);
                for (int c = 0; c < 3; ++c) {
                    const uint32_t want = display_code(rgb[c], bits == 16 ? 65535.f : 255.f);
                    uint32_t got = 0;
                    if (bits == 16) {
                        uint16_t q;
                        std::memcpy(&q, &codes[2 * (3 * i + size_t(c))], 2);
                        got = q;
                    } else {
                        got = codes[3 * i + size_t(c)];
                    }
                    differ += got != want;
                }
            }
            EXPECT_EQ(differ, 0u) << view << " at " << bits << " bits";
        }
        if (std::string(view) == "ACES 1.0 SDR-video") EXPECT_EQ(t.code_table(8), nullptr) << "ACES mixes channels";
        else EXPECT_NE(t.code_table(8), nullptr) << view;
    }
}

TEST(CodeTable, RefusesTransformsThatAreNotPerChannelNonDecreasing) {
    // Decreasing: 1 - x.
    EXPECT_FALSE(CodeTable::build([](float* rgb, size_t n) { for (size_t i = 0; i < 3 * n; ++i) rgb[i] = 1.f - rgb[i]; }, 8));
    // Non-monotone inside the range: a bump the bucket grid cannot see everywhere.
    EXPECT_FALSE(CodeTable::build([](float* rgb, size_t n) {
        for (size_t i = 0; i < 3 * n; ++i) rgb[i] = std::fabs(std::sin(rgb[i] * 40.f));
    }, 8));
    // Crosstalk: red takes green's value.
    EXPECT_FALSE(CodeTable::build([](float* rgb, size_t n) { for (size_t i = 0; i < n; ++i) rgb[3 * i] = rgb[3 * i + 1]; }, 8));
    // A plain per-channel curve is accepted, and its codes are its own.
    const CodeTable::Evaluate gamma = [](float* rgb, size_t n) {
        for (size_t i = 0; i < 3 * n; ++i) rgb[i] = rgb[i] > 0.f ? std::pow(rgb[i], 1.f / 2.2f) : rgb[i];
    };
    const auto table = CodeTable::build(gamma, 8);
    ASSERT_TRUE(table);
    for (float x = -0.5f; x < 1.5f; x += 1.f / 8192.f)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(table->code(c, x), direct_code(gamma, c, x, 8)) << x;
}

}  // namespace
}  // namespace whitted
