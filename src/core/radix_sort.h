// A stable LSD radix sort of 64-bit values by their high 32 bits: Ward's adaptive test orders
// every candidate light of a shading point by its potential (under an environment, up to 256 per
// point, at every hit), and std::sort was 8 % of such a render (a one-thread Duck under studio);
// this takes half that.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace whitted {

/// Sorts `values` ascending by their high 32 bits, keeping the input order among equal high
/// words (stable): when the low words ascend in the input (an index), the result is exactly
/// std::sort's. Four counting passes of 8 bits (a pass whose digit is the same for every value is
/// skipped); below 32 values std::sort itself.
/// `scratch` is resized and reused.
inline void sort_by_high_word(std::vector<uint64_t>& values, std::vector<uint64_t>& scratch) {
    const size_t n = values.size();
    if (n < 32) {
        std::sort(values.begin(), values.end());
        return;
    }
    scratch.resize(n);
    std::vector<uint64_t>* from = &values;
    std::vector<uint64_t>* to = &scratch;
    for (int shift = 32; shift < 64; shift += 8) {
        std::array<uint32_t, 256> count{};
        for (const uint64_t v : *from) ++count[(v >> shift) & 0xff];
        if (count[((*from)[0] >> shift) & 0xff] == n) continue;  // one digit for all: nothing to order
        uint32_t sum = 0;
        for (uint32_t& c : count) {
            const uint32_t here = c;
            c = sum;
            sum += here;
        }
        for (const uint64_t v : *from) (*to)[count[(v >> shift) & 0xff]++] = v;
        std::swap(from, to);
    }
    if (from != &values) values.swap(scratch);
}

}  // namespace whitted
