#include "renderer/film/film.h"

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

}  // namespace whitted
