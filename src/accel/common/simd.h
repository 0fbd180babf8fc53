// Fixed-width float vectors for the wide BVH (bvh/wide_bvh.h), written with the GCC/Clang vector
// extensions rather than intrinsics: the same source compiles to SSE in baseline x86-64 code and
// to single AVX instructions inside a function marked WHITTED_TARGET_AVX2, so one traversal
// template serves both and only the entry point is compiled twice (runtime dispatch on
// cpu_has_avx2(); the project itself keeps the baseline ISA). Element-wise +, -, *, / and
// comparisons are IEEE single precision as in scalar code, and -ffp-contract=off (set for every
// target) keeps the compiler from fusing them: a lane computes bit for bit what the scalar code
// computes.
//
// Rules that keep this portable between GCC and Clang and free of ABI warnings: pass vectors by
// reference, never return a 32-byte vector from a function that is not inlined, and select with
// the vector ternary `mask ? a : b` written out in place.
#pragma once

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define WHITTED_SIMD_X86 1
#else
#define WHITTED_SIMD_X86 0
#endif

#if defined(__GNUC__) || defined(__clang__)
#define WHITTED_ALWAYS_INLINE inline __attribute__((always_inline))
/// The same for a lambda (after its parameter list).
#define WHITTED_ALWAYS_INLINE_LAMBDA __attribute__((always_inline))
/// Inlines every call made in the function (where possible), recursively.
#define WHITTED_FLATTEN __attribute__((flatten))
#else
#define WHITTED_ALWAYS_INLINE inline
#define WHITTED_ALWAYS_INLINE_LAMBDA
#define WHITTED_FLATTEN
#endif

#if WHITTED_SIMD_X86 && (defined(__GNUC__) || defined(__clang__))
/// Compiles one function (and everything inlined into it) for AVX2; call it only when
/// cpu_has_avx2() is true.
#define WHITTED_TARGET_AVX2 __attribute__((target("avx2")))
#define WHITTED_HAS_AVX2_DISPATCH 1
#else
#define WHITTED_TARGET_AVX2
#define WHITTED_HAS_AVX2_DISPATCH 0
#endif

namespace whitted::simd {

template <int N>
struct Types;
template <>
struct Types<4> {
    typedef float vf __attribute__((vector_size(16)));
    typedef int32_t vi __attribute__((vector_size(16)));
};
template <>
struct Types<8> {
    typedef float vf __attribute__((vector_size(32)));
    typedef int32_t vi __attribute__((vector_size(32)));
};

/// N floats / N int32 lanes (comparisons of vfloat yield vint lanes of all ones or all zeros).
template <int N>
using vfloat = typename Types<N>::vf;
template <int N>
using vint = typename Types<N>::vi;

/// True when this CPU runs AVX2 code (checked once).
inline bool cpu_has_avx2() {
#if WHITTED_HAS_AVX2_DISPATCH
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
#else
    return false;
#endif
}

/// Bit i set when lane i of a comparison result is set (movmskps on x86, per 4-lane half).
template <int N>
WHITTED_ALWAYS_INLINE uint32_t lane_mask(const vint<N>& m) {
#if WHITTED_SIMD_X86
    uint32_t bits = 0;
    for (int h = 0; h < N / 4; ++h) {
        __m128 half;
        std::memcpy(&half, reinterpret_cast<const char*>(&m) + 16 * h, 16);
        bits |= uint32_t(_mm_movemask_ps(half)) << (4 * h);
    }
    return bits;
#else
    uint32_t bits = 0;
    for (int i = 0; i < N; ++i) bits |= (m[i] != 0 ? 1u : 0u) << i;
    return bits;
#endif
}

}  // namespace whitted::simd
