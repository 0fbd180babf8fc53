// Output: color management through OpenColorIO and image files through OpenImageIO.
#pragma once

#include <map>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/image_files.h"
#include "film/film.h"
#include "output/code_table.h"
#include "scene/scene.h"

namespace whitted {

/// How to turn scene-linear Rec.709 into display values.
struct ColorSettings {
    std::string config;                   ///< OCIO config path; empty = $OCIO, else the bundled one
    std::string display;                  ///< empty = the config's default display
    std::string view = "Standard";        ///< "Standard" (sRGB curve), "ACES 1.0 SDR-video", "Raw"; empty = the display's default
};

/// Path of the OCIO config shipped with whitted (assets/ocio/config.ocio), found next to the
/// executable's install or source tree.
std::string bundled_ocio_config();

/// A scene-linear -> display processor (OCIO CPU processor, created once, thread-safe to apply).
class DisplayTransform {
public:
    /// Throws whitted::Error naming the config, display or view when one is unknown.
    explicit DisplayTransform(const ColorSettings& settings);
    ~DisplayTransform();
    DisplayTransform(DisplayTransform&&) noexcept;
    /// Transforms packed RGB floats in place (not clamped: OCIO does not clamp).
    void apply(float* rgb, size_t pixel_count) const;
    Color apply(Color c) const;
    /// The code table of this transform for `bits`, built on first use; nullptr for 16 bits
    /// (65535 thresholds cost more to find than one image's transform), or when the transform
    /// mixes channels or fails CodeTable's checks: then codes come from apply().
    const CodeTable* code_table(int bits) const;
    const std::string& config_path() const;
    const std::string& display() const;
    const std::string& view() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// Display-referred codes of scene-linear pixels, exactly as write_image quantises PNG, JPEG and
/// TIFF: NaN -> 0 and +-inf -> +-65504, the transform (OCIO), then clamped to [0, 1] and rounded
/// to `bits`, written into `out` as RGB interleaved: one byte per code for 8 bits, two (uint16_t,
/// native order) for 16. Throws whitted::Error for other bit depths or when `out` is not
/// pixels.size() * 3 codes long.
void display_codes(std::span<const Color> pixels, const DisplayTransform& transform, int bits, std::span<uint8_t> out);

struct OutputSettings {
    ColorSettings color;
    int bits = 0;                         ///< 8 or 16 for PNG/TIFF; 0 = 8 (PNG/JPEG), 16 (TIFF)
    bool exr_half = true;                 ///< EXR beauty as half (true) or float (false)
    /// EXR compression, all lossless: none, rle, zips, zip, piz; zip and zips take a zlib level,
    /// "zip:6" (default 1); exr_compression_error (src/core/image_files_exr.h) checks it.
    /// "zip" by default; "none" writes a float beauty about 3x faster at 3x the bytes
    /// (docs/performance.md, "Output").
    std::string exr_compression = "zip";
    /// TIFF compression, lossless: zip (Deflate with the horizontal predictor, level 1; zip:N for
    /// 1-12) or none; tiff_compression_error (src/core/image_files_display.h) checks it. "none"
    /// writes a 16-bit 1920x1080 TIFF in about 40 ms instead of 53, at about 7x the bytes
    /// (docs/measurements/performance.md, "Output").
    std::string tiff_compression = "zip";
    std::map<std::string, std::string> metadata;  ///< written into EXR headers (and PNG text)
};

/// Fills the output settings the caller did not set (`given`) from a scene file's: the output
/// path ("output"; a relative one is taken relative to the folder of `scene_path`, the scene file,
/// as pbrt does) and the OCIO "view" and "display". Values the file leaves unset keep them as
/// they are.
void apply_scene_output_settings(const SceneRenderSettings& s, const std::string& scene_path, std::string& output_path,
                                 OutputSettings& settings, const SettingGiven& given = {});

/// Writes the film by extension: .exr (scene-linear, AOVs as extra channels, data window =
/// crop), .png/.jpg/.jpeg/.tif/.tiff (display-referred through OCIO, clamped to [0,1]).
/// The file is written to a temporary name and renamed, so it is complete or absent.
/// Throws whitted::Error naming the file on failure (unknown extension, OIIO error).
void write_image(const Film& film, const std::string& path, const OutputSettings& settings);

/// Removes the temporary file of a write in progress, if any (async-signal-safe: for SIGINT/SIGTERM
/// handlers, so an interrupted write leaves nothing behind).
void remove_partial_output() noexcept;

/// An EXR that write_image wrote (beauty and AOV channels by name, data and display windows)
/// read back into a Film, with its string metadata. Throws whitted::Error naming the file when it
/// cannot be read, is not an EXR or lacks the R, G, B channels. Exact for float EXRs.
/// `beauty_type`, when given, receives how the file stores the beauty (Half or Float).
Film read_film(const std::string& path, std::map<std::string, std::string>* metadata = nullptr,
               PixelType* beauty_type = nullptr);

/// Reads an image into linear float RGB (EXR as stored; 8/16-bit files decoded by OIIO as
/// stored, no color conversion). For tests and comparisons.
std::vector<float> read_image_rgb(const std::string& path, int& width, int& height);

}  // namespace whitted
