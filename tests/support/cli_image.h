// Pixels of an image the `whitted` program wrote, for CLI tests that compare outputs (the files'
// headers differ: command line, date).
#pragma once

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <vector>

namespace whitted::test {

/// All channels of the first subimage as float ({} when it cannot be read).
inline std::vector<float> read_pixels(const std::filesystem::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data())) return {};
    return px;
}

}  // namespace whitted::test
