// Film: linear RGB beauty plus optional AOVs for a (possibly cropped) region of an image.
// It only accumulates; output (OCIO + OIIO) lives in src/output.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/vecmath.h"

namespace whitted {

/// Which arbitrary output variables to keep (geometric ones from the pixel-centre camera ray; not
/// filtered).
struct AovSet {
    bool depth = false;     ///< camera-space distance along the ray (t * |dir|), inf when missed
    bool normal = false;    ///< world-space shading normal, 0 when missed
    bool albedo = false;    ///< kd + kr + kt at the first hit (a denoiser-style albedo)
    bool prim_id = false;   ///< triangle index within its mesh, -1 (as uint max) when missed
    bool inst_id = false;   ///< instance index, -1 when missed
    bool aa_samples = false;  ///< primary sample points the pixel's estimate uses (1 center, 4 corners,
                              ///< 4..(2^d+1)^2 adaptive, spp stratified); see docs/antialiasing.md
    /// True when a pixel-centre first hit is needed (every AOV but aa_samples).
    bool needs_first_hit() const { return depth || normal || albedo || prim_id || inst_id; }
    bool any() const { return needs_first_hit() || aa_samples; }
};

/// Region [x0, x1) x [y0, y1) of the full image (the EXR data window).
struct PixelWindow {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool operator==(const PixelWindow&) const = default;
};

/// A tile: a region of the image like any other (a tile's film has the tile as its window).
using TileRect = PixelWindow;

struct Film {
    int full_width = 0, full_height = 0;  ///< the display window
    PixelWindow window;                   ///< rendered region (crop); pixels below are its size
    AovSet aovs;
    std::vector<Color> beauty;            ///< window.width() * window.height(), row-major
    std::vector<float> depth;
    std::vector<Vec3f> normal;
    std::vector<Color> albedo;
    std::vector<uint32_t> prim_id;
    std::vector<uint32_t> inst_id;
    std::vector<float> aa_samples;

    Film() = default;
    /// Allocates the buffers for `window` of a full_width x full_height image.
    Film(int full_width, int full_height, PixelWindow window, AovSet aovs);
    int width() const { return window.width(); }
    int height() const { return window.height(); }
    /// Index of full-image pixel (x, y), which must lie inside the window.
    size_t index(int x, int y) const { return size_t(y - window.y0) * size_t(width()) + size_t(x - window.x0); }
    /// True when `part`'s window lies inside this film's window, with the same image size and AOVs.
    bool can_paste(const Film& part) const;
    /// Copies every buffer of `part` (a tile of the same image, can_paste) into its window here.
    void paste(const Film& part);
    /// NaN or infinite values in the beauty, normal and albedo buffers (depth is +inf for misses
    /// by design and not counted).
    size_t nonfinite_values() const;
    /// Last line of defence before output: replaces every NaN / infinite beauty, normal or albedo
    /// component by 0 and returns how many there were. Debug builds treat any as a bug (RT_DCHECK
    /// throws whitted::Error); release builds count and repair (docs/numerical-stability.md).
    size_t sanitize_nonfinite();
};

}  // namespace whitted
