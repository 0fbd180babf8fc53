// Display codes of a per-channel, non-decreasing transform, found by table instead of evaluated.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace whitted {

/// The largest finite half: the scene-linear value ±inf becomes before the display transform.
inline constexpr float kDisplayInputLimit = 65504.f;

/// A scene-linear channel made safe for a transform: NaN -> 0, clamped to ±65504.
inline float sanitise_linear(float v) { return std::isnan(v) ? 0.f : std::clamp(v, -kDisplayInputLimit, kDisplayInputLimit); }

/// The code of a display value: NaN -> 0, clamped to [0, 1], rounded to nearest (no dithering).
inline uint32_t display_code(float v, float scale) {
    v = std::isnan(v) ? 0.f : std::clamp(v, 0.f, 1.f);
    return static_cast<uint32_t>(v * scale + 0.5f);
}

/// For a transform whose every output channel is a non-decreasing function of its own input
/// channel (the sRGB curve of the Standard view), the code of a value is the number of code
/// thresholds at or below it. The thresholds are found by bisection with the transform itself,
/// so the table gives the transform's own codes; build() checks that against the transform at
/// every threshold's neighbours and at probes over the whole range, and refuses a transform
/// that differs anywhere it looked.
class CodeTable {
public:
    /// Evaluates the transform on packed RGB floats in place.
    using Evaluate = std::function<void(float* rgb, size_t pixel_count)>;

    /// The table of `f` for codes of `bits` (8 or 16), or nothing when f is not per-channel
    /// non-decreasing where the checks looked (then the caller evaluates f itself).
    static std::optional<CodeTable> build(const Evaluate& f, int bits);

    /// The code of channel `c` for a sanitised value (sanitise_linear).
    uint32_t code(int c, float x) const {
        const uint32_t k = key(x);
        const Channel& ch = m_channels[size_t(c)];
        const uint32_t* t = ch.thresholds.data();
        const uint32_t b = k >> kBucketShift;
        uint32_t i = ch.bucket_first[b];
        const uint32_t end = ch.bucket_first[b + 1];
        if (end - i <= 4) {  // the usual case: at most a few thresholds share a bucket
            while (i < end && t[i] <= k) ++i;
            return i;
        }
        return uint32_t(std::upper_bound(t + i, t + end, k) - t);
    }

    /// Floats in an order-preserving uint32: -65504 < ... < -0 < +0 < ... < 65504.
    static uint32_t key(float x) {
        const uint32_t u = std::bit_cast<uint32_t>(x);
        return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
    }
    static float from_key(uint32_t k) { return std::bit_cast<float>((k & 0x80000000u) ? (k & 0x7fffffffu) : ~k); }

private:
    static constexpr uint32_t kBucketShift = 16;  ///< buckets by the key's top 16 bits (7 mantissa bits)
    struct Channel {
        std::vector<uint32_t> thresholds;    ///< key of the smallest value with code >= k + 1, ascending
        std::vector<uint32_t> bucket_first;  ///< per bucket: how many thresholds lie below its first key
    };
    Channel m_channels[3];
};

}  // namespace whitted
