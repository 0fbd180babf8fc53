// split_tail (core/tail_split.h) finds the same untested tail as sorting every candidate and
// scanning from the smallest up, the split Ward's adaptive test needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "core/tail_split.h"
#include "core/vecmath.h"

namespace whitted {
namespace {

/// The reference: keys sorted, the tail grown from the largest key while its sum stays below.
size_t sorted_split(std::vector<uint64_t> keys, const std::vector<Color>& weight, float bar) {
    std::sort(keys.begin(), keys.end());
    size_t b = keys.size();
    Color tail(0.f);
    while (b > 0) {
        const Color more = tail + weight[uint32_t(keys[b - 1])];
        if (!(max_component(more) < bar)) break;
        tail = more;
        --b;
    }
    return b;
}

TEST(TailSplit, EqualsSortingEveryKey) {
    std::mt19937 rng(7);
    size_t cases = 0, middle = 0;
    for (size_t n : {0, 1, 2, 3, 5, 8, 9, 10, 17, 33, 64, 100, 219, 256, 1000}) {
        for (int round = 0; round < 40; ++round) {
            // Whole-number weights: every sum is exact whatever the order, so the split is exact.
            // Keys as Ward's test makes them: a (here coarse, so often tied) potential above the index.
            std::vector<Color> weight(n);
            std::vector<uint64_t> keys(n);
            float total = 0.f;
            for (size_t j = 0; j < n; ++j) {
                weight[j] = Color(float(rng() % 10), float(rng() % 4), float(rng() % 7));
                if (rng() % 5 == 0) weight[j] = Color(0.f);
                total += max_component(weight[j]);
                keys[j] = uint64_t(~uint32_t(rng() % 6)) << 32 | uint64_t(j);
            }
            for (const float bar : {0.f, 1.f, 0.5f * total, 0.1f * total, 2.f * total + 1.f, float(rng() % 50)}) {
                std::vector<uint64_t> got = keys;
                const size_t b = split_tail(std::span<uint64_t>(got), [&](uint64_t k) { return weight[uint32_t(k)]; },
                                            [&](const Color& c) { return max_component(c) < bar; });
                ASSERT_EQ(b, sorted_split(keys, weight, bar)) << "n " << n << " bar " << bar;
                // A rearrangement of the keys, the b smallest first.
                std::vector<uint64_t> a = got, e = keys;
                std::sort(a.begin(), a.end());
                std::sort(e.begin(), e.end());
                ASSERT_EQ(a, e);
                if (b > 0 && b < n) {
                    EXPECT_LT(*std::max_element(got.begin(), got.begin() + ptrdiff_t(b)),
                              *std::min_element(got.begin() + ptrdiff_t(b), got.end()));
                    ++middle;
                }
                ++cases;
            }
        }
    }
    EXPECT_GT(middle, cases / 4);  // most cases split inside, not at an end
}

TEST(TailSplit, ArrangementDependsOnTheInputAlone) {
    std::vector<uint64_t> keys(300);
    for (size_t j = 0; j < keys.size(); ++j) keys[j] = uint64_t((j * 7919) % 300) << 32 | j;
    std::vector<uint64_t> a = keys, b = keys;
    auto weight = [](uint64_t k) { return Color(float(k >> 32) * 0.01f); };
    auto below = [](const Color& c) { return c.x < 40.f; };
    EXPECT_EQ(split_tail(std::span<uint64_t>(a), weight, below), split_tail(std::span<uint64_t>(b), weight, below));
    EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace whitted
