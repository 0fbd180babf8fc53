#include "film/film.h"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "core/error.h"

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

bool Film::can_paste(const Film& part) const {
    const PixelWindow& w = part.window;
    return part.full_width == full_width && part.full_height == full_height && w.x0 >= window.x0 &&
           w.y0 >= window.y0 && w.x1 <= window.x1 && w.y1 <= window.y1 && w.width() > 0 && w.height() > 0 &&
           part.aovs.depth == aovs.depth && part.aovs.normal == aovs.normal && part.aovs.albedo == aovs.albedo &&
           part.aovs.prim_id == aovs.prim_id && part.aovs.inst_id == aovs.inst_id &&
           part.aovs.aa_samples == aovs.aa_samples;
}

namespace {

template <typename T>
void paste_rows(std::vector<T>& dst, const Film& to, const std::vector<T>& src, const Film& from) {
    if (src.empty()) return;
    const PixelWindow& w = from.window;
    for (int y = w.y0; y < w.y1; ++y)
        std::copy_n(src.begin() + std::ptrdiff_t(from.index(w.x0, y)), w.width(),
                    dst.begin() + std::ptrdiff_t(to.index(w.x0, y)));
}

}  // namespace

void Film::paste(const Film& part) {
    RT_CHECK(can_paste(part));
    paste_rows(beauty, *this, part.beauty, part);
    paste_rows(depth, *this, part.depth, part);
    paste_rows(normal, *this, part.normal, part);
    paste_rows(albedo, *this, part.albedo, part);
    paste_rows(prim_id, *this, part.prim_id, part);
    paste_rows(inst_id, *this, part.inst_id, part);
    paste_rows(aa_samples, *this, part.aa_samples, part);
}

size_t Film::nonfinite_values() const { return count_nonfinite(beauty) + count_nonfinite(normal) + count_nonfinite(albedo); }

size_t Film::sanitize_nonfinite() {
    const size_t n = zero_nonfinite(beauty) + zero_nonfinite(normal) + zero_nonfinite(albedo);
    RT_DCHECK(n == 0);
    return n;
}

}  // namespace whitted
