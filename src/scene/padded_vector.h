// TailPaddedAllocator: a std::vector allocator that leaves zeroed bytes after the last element.
#pragma once

#include <cstddef>
#include <cstring>
#include <new>
#include <vector>

namespace whitted {

/// Allocates kTailBytes more than asked for after the capacity() elements, so a reader with wide
/// loads (Embree fetches a FLOAT3 vertex with one 16-byte load) may read past the last element
/// without leaving the allocation. The whole block starts zeroed, so the bytes such a reader sees
/// past size() are initialized too (memory checkers). Stateless: all instances are equal.
template <typename T, size_t kTailBytes>
struct TailPaddedAllocator {
    using value_type = T;
    template <typename U>
    struct rebind {
        using other = TailPaddedAllocator<U, kTailBytes>;
    };

    TailPaddedAllocator() noexcept = default;
    template <typename U>
    TailPaddedAllocator(const TailPaddedAllocator<U, kTailBytes>&) noexcept {}

    /// Room for n elements and the tail, all zero bytes; aligned like operator new (16 bytes).
    T* allocate(size_t n) {
        if (n > (size_t(-1) - kTailBytes) / sizeof(T)) throw std::bad_array_new_length();
        void* p = ::operator new(n * sizeof(T) + kTailBytes);
        std::memset(p, 0, n * sizeof(T) + kTailBytes);
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t) noexcept { ::operator delete(p); }  // unsized: clang declares no sized delete by default

    template <typename U>
    bool operator==(const TailPaddedAllocator<U, kTailBytes>&) const noexcept {
        return true;
    }
};

/// Zeroed bytes after the last element of a PaddedVector: one 16-byte load at the last element.
constexpr size_t kPaddedVectorTailBytes = 16;

/// A std::vector whose allocation holds kPaddedVectorTailBytes zeroed bytes after the last element
/// (Mesh::positions, which the Embree backend hands to Embree without a copy).
template <typename T>
using PaddedVector = std::vector<T, TailPaddedAllocator<T, kPaddedVectorTailBytes>>;

}  // namespace whitted
