// Anti-aliasing: where the primary rays of a pixel go and how their radiance becomes the pixel.
//
// Four modes (docs/antialiasing.md):
//   center      one ray through each pixel centre.
//   corners     one ray through each pixel corner, shared with the neighbours: an m x n window
//               traces exactly (m+1)(n+1) primary rays; pixel = mean of its 4 corners.
//   adaptive    Whitted (1980): start from the shared corners and split a (sub)square into 4 when
//               its corner colours differ by more than a threshold, tracing only the new points
//               (edge midpoints are shared with the neighbours), down to a maximum depth; the
//               pixel is the area-weighted mean of its leaf squares, each the mean of its corners.
//   stratified  k x k jittered samples per pixel, box or tent filter (filter importance
//               sampling, pbrt-v4 FilterSampler), seeded by the pixel index.
//
// Every sample's radiance is a pure function of its image position, so the image does not depend
// on the tile size or the thread count, and a crop renders the same pixels as the full image.
#pragma once

#include <cstdint>
#include <string>

#include "core/vecmath.h"

namespace whitted {

enum class AaMode : uint8_t { Center, Corners, Adaptive, Stratified };
enum class PixelFilter : uint8_t { Box, Tent };
/// How textures are filtered. `Mip`: trilinear MIP lookups over the footprint of the sample
/// spacing (a ray cone per camera ray: the pixel for centre and corners, pixel/k for stratified
/// k x k, the sub-square for adaptive points), so supersampling converges to the box-filtered
/// integral of the point-sampled texture. `None`: every lookup point-samples the finest level, the
/// environment included (Whitted's model exactly).
enum class TextureFilter : uint8_t { Mip, None };

struct AaSettings {
    AaMode mode = AaMode::Center;     ///< sampling mode; the library default is one ray per pixel centre (exact
                                      ///< pixel-centre values for tests), the CLI's default is adaptive
    float threshold = 0.1f;           ///< adaptive: split when the corners' display-referred values differ by
                                      ///< more than this (max over channels of max - min); < 0 = always split
    int depth = 3;                    ///< adaptive: maximum subdivision depth (0..8); sub-squares of 1/2^depth pixel
    int spp = 16;                     ///< stratified: samples per pixel, a square number k*k (1..4096)
    PixelFilter filter = PixelFilter::Box;  ///< stratified: box (1 pixel) or tent (radius 1 pixel)
    TextureFilter texture_filter = TextureFilter::Mip;  ///< texture footprints (docs/antialiasing.md)
};

/// Parses "center", "corners", "adaptive", "stratified"; throws whitted::Error otherwise.
AaMode parse_aa_mode(const std::string& name);
/// Parses "box", "tent"; throws whitted::Error otherwise.
PixelFilter parse_pixel_filter(const std::string& name);
const char* aa_mode_name(AaMode mode);
const char* pixel_filter_name(PixelFilter filter);
/// Parses "mip", "none"; throws whitted::Error otherwise.
TextureFilter parse_texture_filter(const std::string& name);
const char* texture_filter_name(TextureFilter filter);
/// Width of a sample's texture footprint as a fraction of the pixel: 1 for centre and corner
/// samples, 1/k for stratified k x k, and for adaptive point (i, j) of a pixel's 2^depth grid the
/// side of the sub-square whose split created it (a pure function of the point, so a point shared
/// by two pixels or two levels has one footprint): 2^trailing_zeros(i | j | 2^depth) / 2^depth.
float adaptive_point_spacing(int i, int j, int depth);
/// Throws whitted::Error naming the flag when a setting is out of range (depth, spp not k*k).
void validate_aa_settings(const AaSettings& aa);
/// k for spp = k*k, or 0 when spp is not a positive square.
int stratified_side(int spp);

/// The display-referred value the adaptive threshold compares: the sRGB transfer curve of the
/// exposure-scaled linear value clamped to [0, 1] (what the default OCIO view "Standard" shows).
float aa_display_value(float linear);
/// Contrast of a square: max over channels of (max - min) of its corners' display values.
float aa_contrast(const Color& a, const Color& b, const Color& c, const Color& d);
/// The adaptive split test, exactly `aa_contrast(a, b, c, d) > threshold`, but deciding most
/// squares from bounds on the sRGB curve's slope without evaluating it (no pow()).
bool aa_exceeds(const Color& a, const Color& b, const Color& c, const Color& d, float threshold);

/// Offset in [-1, 1] distributed as a tent (triangle) filter of radius 1, from u in [0, 1).
float sample_tent(float u);
/// Deterministic uniform float in [0, 1) from a 64-bit key (SplitMix64 finaliser).
float hash_to_unit_float(uint64_t key);

}  // namespace whitted
