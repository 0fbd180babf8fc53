// sort_by_high_word (core/radix_sort.h) gives std::sort's order on the values Ward's adaptive test
// sorts: a key in the high word (with many ties, and keys that share their top digits) above an
// index that ascends in the input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/radix_sort.h"

namespace whitted {
namespace {

TEST(RadixSort, EqualsStdSortOnIndexedKeys) {
    std::mt19937 rng(7);
    std::vector<uint64_t> scratch;
    for (const size_t n : {0u, 1u, 5u, 31u, 32u, 33u, 100u, 256u, 1000u}) {
        for (const uint32_t spread : {1u, 3u, 1000u, 0xffffffffu}) {
            std::vector<uint64_t> v(n);
            std::uniform_int_distribution<uint32_t> key(0, spread - 1);
            for (size_t j = 0; j < n; ++j) v[j] = uint64_t(0x3f000000u + key(rng) % spread) << 32 | uint64_t(j);
            std::vector<uint64_t> expected = v;
            std::sort(expected.begin(), expected.end());
            sort_by_high_word(v, scratch);
            ASSERT_EQ(v, expected) << "n " << n << ", spread " << spread;
        }
    }
}

TEST(RadixSort, StableAmongEqualKeys) {
    std::vector<uint64_t> v, scratch;
    for (uint64_t j = 0; j < 100; ++j) v.push_back(uint64_t(j % 2 ? 5 : 9) << 32 | (1000 - j));  // low words descend
    sort_by_high_word(v, scratch);
    for (size_t k = 1; k < v.size(); ++k) {
        if ((v[k] >> 32) != (v[k - 1] >> 32)) continue;
        EXPECT_LT(uint32_t(v[k]), uint32_t(v[k - 1])) << k;  // input order kept, not the low word's
    }
    EXPECT_EQ(v.front() >> 32, 5u);
}

}  // namespace
}  // namespace whitted
