#include "integrator/aa_sampler.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/error.h"

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

TextureFilter parse_texture_filter(const std::string& name) {
    if (name == "mip") return TextureFilter::Mip;
    if (name == "none") return TextureFilter::None;
    throw Error(fmt::format("--texture-filter: unknown filter '{}' (available: mip, none)", name));
}

const char* texture_filter_name(TextureFilter filter) { return filter == TextureFilter::Mip ? "mip" : "none"; }

float adaptive_point_spacing(int i, int j, int depth) {
    const unsigned n = 1u << depth;
    return float(1u << std::countr_zero(unsigned(i) | unsigned(j) | n)) / float(n);
}

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

namespace {

/// Bounds on the slope of aa_display_value() between two clamped values, by binary exponent.
/// The curve's derivative is 12.92 on the linear segment (v <= 0.0031308) and
/// (1.055 / 2.4) v^(1/2.4 - 1) above it, falling from 12.70 to 0.4396 at v = 1, so on [lo, hi]:
/// - the slope is at most 12.92, and at most f'(lo) when lo is above the linear segment;
///   kSlopeAbove[u] bounds it for lo in [2^-(u+1), 2^-u) (u = 8: anything below 2^-8, 12.92);
/// - the slope is at least f'(hi); kSlopeBelow[m] bounds it for hi in [2^-m, 2^-(m-1)) (m = 0:
///   hi = 1, f'(1); m >= 10: hi below 2^-9, inside the linear segment, 12.92).
/// Values f'(2^-k) from the formula in double precision, widened by 0.1 % (upper x 1.001, lower
/// x 0.999) for the float constants of aa_display_value().
constexpr float kSlopeAbove[9] = {0.659289f, 0.987818f, 1.480055f, 2.217577f, 3.322611f,
                                  4.978291f, 7.459009f, 11.175885f, 12.93292f};
constexpr float kSlopeBelow[11] = {0.439144f, 0.439144f, 0.657972f, 0.985844f, 1.477098f, 2.213146f,
                                   3.315972f, 4.968344f, 7.444106f, 11.153556f, 12.90708f};
/// Absolute slack for everything the slope bounds leave out: powf's error (< 1 ulp), the rounding
/// of the formula and of the bound's own product, the curve's jump of ~3e-8 at 0.0031308 (the two
/// segments do not quite meet). All are below 1e-6 on values in [0, 1].
constexpr float kSlack = 1e-5f;

/// Biased binary exponent of a non-negative float (0 for 0).
int biased_exponent(float v) { return int(std::bit_cast<uint32_t>(v) >> 23); }

}  // namespace

bool aa_exceeds(const Color& a, const Color& b, const Color& c, const Color& d, float threshold) {
    // aa_contrast() starts from 0 and takes maxima, so it is >= 0: a negative threshold always splits.
    if (threshold < 0.f) return true;
    for (int i = 0; i < 3; ++i) {
        const float lo = std::min(std::min(a[i], b[i]), std::min(c[i], d[i]));
        const float hi = std::max(std::max(a[i], b[i]), std::max(c[i], d[i]));
        if (hi == lo) continue;  // aa_contrast() skips flat channels
        // aa_contrast()'s channel term is f(hi) - f(lo) for the clamped values: bound it by the
        // slope bounds times their difference, and evaluate it only when the bounds straddle the threshold.
        const float clo = std::clamp(lo, 0.f, 1.f), chi = std::clamp(hi, 0.f, 1.f);
        const float span = chi - clo;
        const float above = kSlopeAbove[std::clamp(126 - biased_exponent(clo), 0, 8)] * span + kSlack;
        if (above <= threshold) continue;
        const float below = kSlopeBelow[std::clamp(127 - biased_exponent(chi), 0, 10)] * span - kSlack;
        if (below > threshold) return true;
        if (aa_display_value(hi) - aa_display_value(lo) > threshold) return true;
    }
    return false;
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
