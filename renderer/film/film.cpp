#include "renderer/film/film.h"

#include <cmath>

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

template <typename V>
size_t count_nonfinite(const std::vector<V>& buffer) {
    size_t n = 0;
    for (const V& v : buffer)
        for (int k = 0; k < 3; ++k) n += !std::isfinite(v[k]);
    return n;
}

template <typename V>
size_t zero_nonfinite(std::vector<V>& buffer) {
    size_t n = 0;
    for (V& v : buffer)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(v[k])) v[k] = 0.f, ++n;
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
