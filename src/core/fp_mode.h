// The floating-point mode tracing runs in: flush-to-zero and denormals-are-zero (SSE MXCSR),
// which Embree expects in every thread that traces; ray offsets never step into the denormals
// (src/core/ray_offset.h). Scoped, because the renderer is a library: the caller's mode is
// restored when the scope ends. Render worker threads get the same through a TBB observer.
#pragma once

#include <xmmintrin.h>

namespace whitted {

/// FTZ and DAZ on for the lifetime of the object in the calling thread; the previous MXCSR
/// (rounding mode, exception masks and sticky flags included) is restored by the destructor.
class ScopedFlushDenormals {
public:
    ScopedFlushDenormals() : m_saved(_mm_getcsr()) { _mm_setcsr(m_saved | kFtz | kDaz); }
    ~ScopedFlushDenormals() { _mm_setcsr(m_saved); }
    ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
    ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

    static constexpr unsigned kFtz = 0x8000;  ///< _MM_FLUSH_ZERO_ON
    static constexpr unsigned kDaz = 0x0040;  ///< _MM_DENORMALS_ZERO_ON

private:
    unsigned m_saved;
};

}  // namespace whitted
