// The split at the heart of Ward's adaptive test (integrator/whitted_integrator.cpp): of n
// candidates ordered by a key, the longest tail whose summed weight stays below a bar, found by
// selection instead of a sort. Under an environment a shading point weighs up to 256 extracted
// lights, and ordering them all (std::sort, then a radix sort) was 5-10 % of such renders; the
// test needs only which candidates fall in the tail, not their order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

namespace whitted {

/// Rearranges `keys` (distinct values; a smaller key is a candidate tested earlier) and returns b
/// such that keys[0, b) are the b smallest keys and keys[b, n) the others, b being the smallest
/// count for which below(the sum of weight(k) over keys[b, n)) holds: the untested tail is the
/// longest run of the largest keys whose weights together stay below the bar. b = n when no tail
/// qualifies (below(0) is never asked); b = 0 when all of them together qualify.
/// weight(k) returns a value with += (not negative, so a tail's sum grows with its length);
/// below(sum) is the bar. Expected O(n): quickselect on the sums (median-of-three pivots), the last
/// few keys ordered by insertion. The arrangement is a function of the input alone.
template <typename Weight, typename Below>
size_t split_tail(std::span<uint64_t> keys, Weight weight, Below below) {
    using Sum = std::remove_cvref_t<decltype(weight(uint64_t(0)))>;
    size_t lo = 0, hi = keys.size();
    Sum tail{};  // the weights of keys[hi, n): known to be in the tail
    while (hi - lo > 8) {
        // Median of three as the pivot: some key of the range is below it and it is in the range,
        // so both sides of the partition are non-empty.
        const size_t mid = lo + (hi - lo) / 2;
        const uint64_t a = keys[lo], b = keys[mid], c = keys[hi - 1];
        const uint64_t pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        size_t m = lo;
        for (size_t k = lo; k < hi; ++k)
            if (keys[k] < pivot) std::swap(keys[k], keys[m++]);
        Sum upper = tail;
        for (size_t k = m; k < hi; ++k) upper += weight(keys[k]);
        if (below(upper)) {
            tail = upper;  // all of keys[m, n) are in the tail; the split lies in [lo, m]
            hi = m;
        } else {
            lo = m;  // keys[lo, m) are tested; the split lies in [m, hi)
        }
    }
    // The last few keys in order, then taken into the tail from the largest down.
    for (size_t k = lo + 1; k < hi; ++k)
        for (size_t j = k; j > lo && keys[j] < keys[j - 1]; --j) std::swap(keys[j], keys[j - 1]);
    while (hi > lo) {
        Sum more = tail;
        more += weight(keys[hi - 1]);
        if (!below(more)) break;
        tail = more;
        --hi;
    }
    return hi;
}

}  // namespace whitted
