// An image file (OpenImageIO, through src/core/image_files.h) -> RGBA8 texture level (scene-file image textures).

#include "importers/scene_file_image.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "importers/image_decode.h"
#include "importers/one_line.h"
#include "core/image_files.h"
#include "shading/texture_sampling.h"

namespace whitted {

namespace {
void read_pixels(ImageFileReader& in, int channels, PixelType type, void* out, const std::string& file,
                 const FileLoc& loc) {
    try {
        in.read(0, channels, type, out);
    } catch (const Error& e) {
        throw Error(loc, fmt::format("cannot read image '{}': {}", file, one_line(e.what())));
    }
}

}  // namespace

LoadedImage load_image_file(const std::string& file, size_t max_memory, const FileLoc& loc) {
    std::unique_ptr<ImageFileReader> in;
    try {
        in = open_image_file(file);
    } catch (const Error& e) {
        const std::string why = one_line(e.what());
        throw Error(loc, fmt::format("cannot read image '{}': {}", file, why.empty() ? "unknown format" : why));
    }
    const ImageDesc& spec = in->desc();
    // The header first: a small file must not make us allocate a huge image.
    if (spec.depth > 1) throw Error(loc, fmt::format("image '{}' is a volume ({} slices): not supported", file, spec.depth));
    if (const std::string refused = check_image_size(spec.width, spec.height, max_memory); !refused.empty())
        throw Error(loc, fmt::format("image '{}' refused: {}", file, refused));
    if (spec.channels() < 1) throw Error(loc, fmt::format("image '{}' has no channels", file));

    const int channels = std::min(spec.channels(), 4);
    const bool is_float = spec.floating_point;
    const size_t texels = size_t(spec.width) * size_t(spec.height);
    LoadedImage out;
    out.float_data = is_float;
    out.level.width = spec.width;
    out.level.height = spec.height;
    out.level.texels.resize(texels * 4);

    // Expand 1 (gray), 2 (gray, alpha), 3 (RGB) or 4 channels to RGBA.
    if (is_float) {
        std::vector<float> px(texels * size_t(channels));
        read_pixels(*in, channels, PixelType::Float, px.data(), file, loc);
        for (size_t i = 0; i < texels; ++i) {
            const float* v = &px[i * size_t(channels)];
            uint8_t* o = &out.level.texels[i * 4];
            const float r = v[0], g = channels >= 3 ? v[1] : v[0], b = channels >= 3 ? v[2] : v[0];
            const float a = channels == 2 ? v[1] : channels == 4 ? v[3] : 1.f;
            o[0] = linear_to_srgb8(r), o[1] = linear_to_srgb8(g), o[2] = linear_to_srgb8(b);
            o[3] = uint8_t(std::lround(std::clamp(std::isfinite(a) ? a : 0.f, 0.f, 1.f) * 255.f));
        }
    } else {
        std::vector<uint8_t> px(texels * size_t(channels));
        read_pixels(*in, channels, PixelType::UInt8, px.data(), file, loc);
        for (size_t i = 0; i < texels; ++i) {
            const uint8_t* v = &px[i * size_t(channels)];
            uint8_t* o = &out.level.texels[i * 4];
            o[0] = v[0];
            o[1] = channels >= 3 ? v[1] : v[0];
            o[2] = channels >= 3 ? v[2] : v[0];
            o[3] = channels == 2 ? v[1] : channels == 4 ? v[3] : 255;
        }
    }
    return out;
}

}  // namespace whitted
