// libwhitted_oiio.so: the OpenImageIO calls behind src/core/image_files.h, in a module of
// their own so that only a process that opens an image file loads OIIO (see the header). It
// links nothing of whitted; exceptions never leave it.
#include <exception>
#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

#include "core/image_files.h"

namespace {

OIIO::TypeDesc to_oiio(whitted::PixelType t) {
    switch (t) {
        case whitted::PixelType::UInt8: return OIIO::TypeUInt8;
        case whitted::PixelType::UInt16: return OIIO::TypeUInt16;
        case whitted::PixelType::UInt32: return OIIO::TypeUInt;
        case whitted::PixelType::Half: return OIIO::TypeHalf;
        case whitted::PixelType::Float: return OIIO::TypeFloat;
    }
    return OIIO::TypeUnknown;
}

/// The nearest PixelType holding a stored format (other types: float when floating, else
/// the unsigned integer of at least its size).
whitted::PixelType from_oiio(OIIO::TypeDesc t) {
    if (t == OIIO::TypeHalf) return whitted::PixelType::Half;
    if (t.is_floating_point()) return whitted::PixelType::Float;
    if (t.size() <= 1) return whitted::PixelType::UInt8;
    if (t.size() <= 2) return whitted::PixelType::UInt16;
    return whitted::PixelType::UInt32;
}

void describe(const OIIO::ImageSpec& spec, const char* format_name, whitted::ImageDesc& d) {
    d.width = spec.width;
    d.height = spec.height;
    d.depth = spec.depth;
    d.x = spec.x;
    d.y = spec.y;
    d.full_x = spec.full_x;
    d.full_y = spec.full_y;
    d.full_width = spec.full_width;
    d.full_height = spec.full_height;
    d.alpha_channel = spec.alpha_channel;
    d.z_channel = spec.z_channel;
    d.floating_point = spec.format.is_floating_point();
    d.format_name = format_name;
    d.channel_names.clear();
    d.channel_types.clear();
    for (int c = 0; c < spec.nchannels; ++c) {
        d.channel_names.push_back(c < int(spec.channelnames.size()) ? spec.channelnames[size_t(c)] : std::string());
        d.channel_types.push_back(from_oiio(spec.channelformat(c)));
    }
    d.attributes.clear();
    for (const OIIO::ParamValue& p : spec.extra_attribs)
        if (p.type() == OIIO::TypeString) d.attributes.emplace_back(p.name().string(), p.get_string());
}

OIIO::ImageSpec to_spec(const whitted::ImageDesc& d, OIIO::TypeDesc& buffer_format) {
    const size_t n = d.channel_types.size();
    bool uniform = true;
    for (size_t c = 1; c < n; ++c) uniform = uniform && d.channel_types[c] == d.channel_types[0];
    const OIIO::TypeDesc first = n > 0 ? to_oiio(d.channel_types[0]) : OIIO::TypeFloat;
    OIIO::ImageSpec spec(d.width, d.height, int(n), uniform ? first : OIIO::TypeFloat);
    spec.channelnames = d.channel_names;
    if (!uniform) {
        spec.channelformats.clear();
        for (whitted::PixelType t : d.channel_types) spec.channelformats.push_back(to_oiio(t));
    }
    spec.alpha_channel = d.alpha_channel;
    spec.z_channel = d.z_channel;
    spec.x = d.x;
    spec.y = d.y;
    spec.full_x = d.full_x;
    spec.full_y = d.full_y;
    spec.full_width = d.full_width > 0 ? d.full_width : d.width;
    spec.full_height = d.full_height > 0 ? d.full_height : d.height;
    for (const auto& [key, value] : d.attributes) spec.attribute(key, value);
    // Uniform channels: a buffer of that type; mixed: every channel in its own (native) type.
    buffer_format = uniform ? first : OIIO::TypeUnknown;
    return spec;
}

void* open_file(const char* path, whitted::ImageDesc* desc, std::string* error) {
    try {
        std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
        if (!in) {
            *error = OIIO::geterror();
            return nullptr;
        }
        describe(in->spec(), in->format_name(), *desc);
        return in.release();
    } catch (const std::exception& e) {
        *error = e.what();
    } catch (...) {
        *error = "unknown OpenImageIO failure";
    }
    return nullptr;
}

bool read_file(void* file, int first, int last, whitted::PixelType type, void* out, std::string* error) {
    try {
        auto* in = static_cast<OIIO::ImageInput*>(file);
        if (in->read_image(0, 0, first, last, to_oiio(type), out)) return true;
        *error = in->geterror();
        if (error->empty()) *error = "read failed";
    } catch (const std::exception& e) {
        *error = e.what();
    } catch (...) {
        *error = "unknown OpenImageIO failure";
    }
    return false;
}

void close_file(void* file) {
    auto* in = static_cast<OIIO::ImageInput*>(file);
    try {
        in->close();
    } catch (...) {
    }
    delete in;
}

bool write_file(const char* path, const whitted::ImageDesc* desc, const void* pixels, void (*before_pixels)(),
                std::string* error) {
    try {
        OIIO::TypeDesc buffer_format;
        const OIIO::ImageSpec spec = to_spec(*desc, buffer_format);
        std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(desc->format_name);
        if (!out) {
            *error = OIIO::geterror();
            return false;
        }
        if (!out->open(path, spec)) {
            *error = out->geterror();
            return false;
        }
        if (before_pixels) before_pixels();
        if (!out->write_image(buffer_format, pixels)) {
            *error = out->geterror();
            out->close();
            return false;
        }
        if (!out->close()) {
            *error = out->geterror();
            return false;
        }
        return true;
    } catch (const std::exception& e) {
        *error = e.what();
    } catch (...) {
        *error = "unknown OpenImageIO failure";
    }
    return false;
}

constexpr whitted::ImageModuleApi kApi{whitted::kImageModuleVersion, open_file, read_file, close_file, write_file};

}  // namespace

extern "C" __attribute__((visibility("default"))) const whitted::ImageModuleApi* whitted_image_module() {
    return &kApi;
}
