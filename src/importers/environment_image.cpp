// An image file (OpenImageIO, through src/core/image_files.h) -> EnvironmentImage (linear RGB), with the limits checked from the header first.

#include "importers/environment_image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "importers/image_decode.h"
#include "importers/one_line.h"
#include "core/data_files.h"
#include "core/error.h"
#include "core/image_files.h"
#include "shading/environment_map.h"

namespace whitted {

namespace {

/// sRGB transfer -> linear (IEC 61966-2-1) for a value in [0, 1].
float srgb_to_linear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

}  // namespace

const std::vector<std::string>& bundled_environment_names() {
    static const std::vector<std::string> names{"studio", "city", "courtyard", "forest", "interior", "sunset", "furnace"};
    return names;
}

std::string resolve_environment_name(const std::string& name) {
    // An existing file wins; a folder of the same name (a "studio" folder in the working
    // directory) does not hide the bundled map.
    std::error_code ec;
    if (std::filesystem::is_regular_file(name, ec)) return name;
    const auto& names = bundled_environment_names();
    if (std::find(names.begin(), names.end(), name) != names.end())
        return data_file("environments/" + name + ".exr");
    throw Error(fmt::format("environment '{}': no such file, and not a bundled name ({})", name, fmt::join(names, ", ")));
}

bool is_bundled_environment(const std::string& path) {
    for (const std::string& name : bundled_environment_names())
        for (const std::string& c : data_file_candidates("environments/" + name + ".exr"))
            if (path == c) return true;
    return false;
}

size_t environment_load_bytes(int width, int height, int channels) {
    const size_t texels = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
    return texels * size_t(std::max(channels, 1)) * sizeof(float) + texels * sizeof(Color) +
           EnvironmentMap::estimated_bytes(width, height);
}

EnvironmentImage load_environment_image(const std::string& path, size_t max_memory_bytes,
                                        std::vector<std::string>& warnings) {
    FileLoc loc;
    loc.file = path;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(loc, "cannot read the environment map: no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(loc, "cannot read the environment map: not a file");
    std::unique_ptr<ImageFileReader> in;
    try {
        in = open_image_file(path);
    } catch (const Error& e) {
        const std::string why = one_line(e.what());
        throw Error(loc, fmt::format("cannot read the environment map: not an image whitted reads ({})",
                                     why.empty() ? "unknown format" : why));
    }

    // The header first: a small file must not make us allocate a huge image.
    const ImageDesc& spec = in->desc();
    if (spec.width < 1 || spec.height < 1 || spec.channels() < 1)
        throw Error(loc, fmt::format("the environment map is empty ({}x{}, {} channels)", spec.width, spec.height,
                                     spec.channels()));
    if (spec.depth > 1) throw Error(loc, fmt::format("the environment map is a volume ({} slices)", spec.depth));
    if (spec.width > kMaxImageSide || spec.height > kMaxImageSide)
        throw Error(loc, fmt::format("the environment map is {}x{}, more than the {} texels per side whitted accepts",
                                     spec.width, spec.height, kMaxImageSide));
    const int channels = spec.channels() >= 3 ? 3 : 1;  // RGB, or grey (a second channel is alpha)
    const size_t needed = environment_load_bytes(spec.width, spec.height, channels);
    if (needed > max_memory_bytes)
        throw Error(loc, fmt::format("the environment map is {}x{}: loading it needs about {} MiB, more than the limit "
                                     "of {} MiB (--max-memory)",
                                     spec.width, spec.height, (needed + (1u << 20) - 1) >> 20, max_memory_bytes >> 20));
    if (spec.width != 2 * spec.height)
        warnings.push_back(fmt::format("environment map '{}' is {}x{}, not 2:1: a lat-long map spans 360 x 180 "
                                       "degrees, so its texels are stretched",
                                       path, spec.width, spec.height));

    // Integer files hold sRGB-encoded values (PNG, JPEG) unless they say they are linear.
    const std::string color_space = spec.attribute("oiio:ColorSpace");
    const bool srgb = !spec.floating_point && color_space != "Linear" && color_space != "linear";

    const size_t texels = size_t(spec.width) * size_t(spec.height);
    EnvironmentImage image;
    image.name = std::filesystem::path(path).stem().string();
    image.path = path;
    image.width = spec.width;
    image.height = spec.height;
    image.texels.resize(texels);
    // RGB is read straight into the texels (a Color is three floats); grey into a buffer first.
    static_assert(sizeof(Color) == 3 * sizeof(float));
    std::vector<float> grey(channels == 1 ? texels : 0);
    try {
        in->read(0, channels, PixelType::Float, channels == 3 ? static_cast<void*>(image.texels.data()) : grey.data());
    } catch (const Error& e) {
        throw Error(loc, fmt::format("cannot read the environment map: {}", one_line(e.what())));
    }

    size_t clamped = 0;
    for (size_t i = 0; i < texels; ++i) {
        const Color v = channels == 3 ? image.texels[i] : Color(grey[i]);
        float rgb[3] = {v.x, v.y, v.z};
        bool bad = false;
        for (float& c : rgb) {
            if (!std::isfinite(c) || c < 0.f) {
                c = 0.f;
                bad = true;
            }
            if (srgb) c = srgb_to_linear(std::min(c, 1.f));
        }
        clamped += bad ? 1 : 0;
        image.texels[i] = {rgb[0], rgb[1], rgb[2]};
    }
    if (clamped > 0)
        warnings.push_back(fmt::format("environment map '{}': {} texels with negative, NaN or infinite values set to 0",
                                       path, clamped));
    return image;
}

}  // namespace whitted
