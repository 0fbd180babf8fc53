// Scratch arrays whose elements are left uninitialised: for per-batch buffers (64 rays, 64 hit
// records) that a callee fills completely before anything reads them, where std::array would run
// the elements' default member initializers on every batch (docs/performance.md).
#pragma once

#include <cstddef>
#include <span>
#include <type_traits>

namespace whitted {

template <typename T, size_t N>
union UninitializedArray {
    static_assert(std::is_trivially_destructible_v<T> && std::is_trivially_copyable_v<T>,
                  "only for plain records that are written before they are read");
    UninitializedArray() {}  // user-provided and empty: the members are not initialised
    T at[N];
    /// The first n elements (n <= N).
    std::span<T> first(size_t n) { return std::span<T>(at, n); }
};

}  // namespace whitted
