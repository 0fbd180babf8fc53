#include "renderer/integrator/aa_sampler.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/error.h"

namespace whitted {

AaMode parse_aa_mode(const std::string& name) {
    if (name == "center" || name == "centre") return AaMode::Center;
    if (name == "corners") return AaMode::Corners;
    if (name == "adaptive") return AaMode::Adaptive;
    if (name == "stratified") return AaMode::Stratified;
    throw Error(fmt::format("--aa: unknown mode '{}' (available: center, corners, adaptive, stratified)", name));
}

PixelFilter parse_pixel_filter(const std::string& name) {
    if (name == "box") return PixelFilter::Box;
    if (name == "tent") return PixelFilter::Tent;
    throw Error(fmt::format("--filter: unknown filter '{}' (available: box, tent)", name));
}

const char* aa_mode_name(AaMode mode) {
    switch (mode) {
        case AaMode::Center: return "center";
        case AaMode::Corners: return "corners";
        case AaMode::Adaptive: return "adaptive";
        case AaMode::Stratified: return "stratified";
    }
    return "?";
}

const char* pixel_filter_name(PixelFilter filter) { return filter == PixelFilter::Box ? "box" : "tent"; }

int stratified_side(int spp) {
    if (spp < 1) return 0;
    const int k = int(std::lround(std::sqrt(double(spp))));
    return k * k == spp ? k : 0;
}

void validate_aa_settings(const AaSettings& aa) {
    if (aa.depth < 0 || aa.depth > 8) throw Error(fmt::format("--aa-depth must be in 0..8 (got {})", aa.depth));
    if (!std::isfinite(aa.threshold)) throw Error("--aa-threshold must be a finite number");
    if (aa.spp < 1 || aa.spp > 4096 || stratified_side(aa.spp) == 0)
        throw Error(fmt::format("--spp must be a square number k*k in 1..4096 (got {})", aa.spp));
}

float aa_display_value(float linear) {
    // IEC 61966-2-1 sRGB encoding of the clamped value.
    const float v = std::clamp(linear, 0.f, 1.f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

float aa_contrast(const Color& a, const Color& b, const Color& c, const Color& d) {
    float contrast = 0.f;
    for (int i = 0; i < 3; ++i) {
        // Compare the linear values first: most squares are flat and need no pow().
        const float lo = std::min(std::min(a[i], b[i]), std::min(c[i], d[i]));
        const float hi = std::max(std::max(a[i], b[i]), std::max(c[i], d[i]));
        if (hi == lo) continue;
        contrast = std::max(contrast, aa_display_value(hi) - aa_display_value(lo));
    }
    return contrast;
}

float sample_tent(float u) {
    // Inverse CDF of the tent of radius 1 on [-1, 1] (pbrt-v4 SampleTent).
    if (u < 0.5f) return std::sqrt(2.f * u) - 1.f;
    return 1.f - std::sqrt(2.f - 2.f * u);
}

float hash_to_unit_float(uint64_t key) {
    // SplitMix64 finaliser (Steele et al. 2014), then the top 24 bits as a float in [0, 1).
    uint64_t z = key + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return float(z >> 40) * 0x1p-24f;
}

}  // namespace whitted
