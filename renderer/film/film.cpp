#include "renderer/film/film.h"

#include <bit>
#include <cstdint>

#include "renderer/core/error.h"

namespace whitted {

Film::Film(int full_width_, int full_height_, PixelWindow window_, AovSet aovs_)
    : full_width(full_width_), full_height(full_height_), window(window_), aovs(aovs_) {
    size_t n = size_t(window.width()) * size_t(window.height());
    beauty.assign(n, Color(0.f));
    if (aovs.depth) depth.assign(n, kInfinity);
    if (aovs.normal) normal.assign(n, Vec3f(0.f));
    if (aovs.albedo) albedo.assign(n, Color(0.f));
    if (aovs.prim_id) prim_id.assign(n, 0xffffffffu);
    if (aovs.inst_id) inst_id.assign(n, 0xffffffffu);
    if (aovs.aa_samples) aa_samples.assign(n, 0.f);
}

namespace {

/// NaN or infinity: all exponent bits set. A bit test rather than std::isfinite, component by
/// component without Vec3::operator[]'s branches, so the loops below vectorise.
inline bool nonfinite(float x) { return (std::bit_cast<uint32_t>(x) & 0x7f800000u) == 0x7f800000u; }

template <typename V>
size_t count_nonfinite(const std::vector<V>& buffer) {
    // The components as one float array (Vec3<float> is three packed floats, as the output writes it).
    static_assert(sizeof(V) == 3 * sizeof(float));
    const float* f = reinterpret_cast<const float*>(buffer.data());
    size_t n = 0;
    for (size_t i = 0, size = buffer.size() * 3; i < size; ++i) n += nonfinite(f[i]);
    return n;
}

template <typename V>
size_t zero_nonfinite(std::vector<V>& buffer) {
    // Counted first (vectorised); the buffer is only written when something needs repair.
    const size_t n = count_nonfinite(buffer);
    if (n == 0) return 0;
    for (V& v : buffer) {
        if (nonfinite(v.x)) v.x = 0.f;
        if (nonfinite(v.y)) v.y = 0.f;
        if (nonfinite(v.z)) v.z = 0.f;
    }
    return n;
}

}  // namespace

size_t Film::nonfinite_values() const { return count_nonfinite(beauty) + count_nonfinite(normal) + count_nonfinite(albedo); }

size_t Film::sanitize_nonfinite() {
    const size_t n = zero_nonfinite(beauty) + zero_nonfinite(normal) + zero_nonfinite(albedo);
    RT_DCHECK(n == 0);
    return n;
}

}  // namespace whitted
