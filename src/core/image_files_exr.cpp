// EXR files through OpenEXR itself (11 shared libraries, no measurable start-up), so that the
// bundled environment maps, checkpoints and EXR renders never load OpenImageIO; compression runs
// on OpenEXR's thread pool. Channels are presented as OIIO presents them (R, G, B, A first, then
// the rest in the file's order), so callers see the same layout through either path.
#include "core/image_files_exr.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>
#include <thread>

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>

#include <fmt/format.h>

#include "core/error.h"

namespace whitted {

namespace {

Imf::PixelType to_exr(PixelType t) {
    switch (t) {
        case PixelType::Half: return Imf::HALF;
        case PixelType::UInt32: return Imf::UINT;
        default: return Imf::FLOAT;
    }
}

PixelType from_exr(Imf::PixelType t) {
    switch (t) {
        case Imf::HALF: return PixelType::Half;
        case Imf::UINT: return PixelType::UInt32;
        default: return PixelType::Float;
    }
}

const char* compression_name(Imf::Compression c) {
    switch (c) {
        case Imf::NO_COMPRESSION: return "none";
        case Imf::RLE_COMPRESSION: return "rle";
        case Imf::ZIPS_COMPRESSION: return "zips";
        case Imf::ZIP_COMPRESSION: return "zip";
        case Imf::PIZ_COMPRESSION: return "piz";
        case Imf::PXR24_COMPRESSION: return "pxr24";
        case Imf::B44_COMPRESSION: return "b44";
        case Imf::B44A_COMPRESSION: return "b44a";
        case Imf::DWAA_COMPRESSION: return "dwaa";
        case Imf::DWAB_COMPRESSION: return "dwab";
        default: return "unknown";
    }
}

/// A "compression" attribute the writer takes: a lossless codec, zip and zips with an optional
/// zlib level ("zip:6"; default 1, chosen by measurement on a 1920x1080 half beauty,
/// benchmarks/bench_output.cpp, docs/measurements/performance.md "Output": 10 % larger than level 3
/// at 3/4 of the time). A file without the attribute is written zip:1.
struct ExrCompression {
    Imf::Compression codec = Imf::ZIP_COMPRESSION;
    int level = 1;
};

/// Parses `name` into `out`; returns why not when it is not one the writer takes.
std::string parse_compression(const std::string& name, ExrCompression& out) {
    const size_t colon = name.find(':');
    const std::string method = name.substr(0, colon);
    if (method == "none") out.codec = Imf::NO_COMPRESSION;
    else if (method == "rle") out.codec = Imf::RLE_COMPRESSION;
    else if (method == "zips") out.codec = Imf::ZIPS_COMPRESSION;
    else if (method == "zip") out.codec = Imf::ZIP_COMPRESSION;
    else if (method == "piz") out.codec = Imf::PIZ_COMPRESSION;
    else
        return fmt::format("unknown EXR compression '{}' (use none, rle, zips, zip or piz; zip and zips take a "
                           "level, e.g. zip:6)", name);
    if (colon == std::string::npos) return {};
    const std::string level = name.substr(colon + 1);
    if (method != "zip" && method != "zips") return fmt::format("EXR compression '{}' takes no level", method);
    if (level.size() != 1 || level[0] < '1' || level[0] > '9')
        return fmt::format("EXR compression '{}': the zlib level is 1 to 9", name);
    out.level = level[0] - '0';
    return {};
}

/// OpenEXR's worker threads, once: all cores (files are identical for any count).
void use_all_cores() {
    static const bool once = [] {
        Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
        return true;
    }();
    (void)once;
}

int channel_rank(const std::string& name) {
    static const char* const first[] = {"R", "G", "B", "A"};
    for (int i = 0; i < 4; ++i)
        if (name == first[i]) return i;
    return 4;
}

class ExrReader final : public ImageFileReader {
public:
    explicit ExrReader(const std::string& path) : m_file(path.c_str()) {
        const Imf::Header& h = m_file.header();
        const Imath::Box2i dw = h.dataWindow(), disp = h.displayWindow();
        m_desc.format_name = "openexr";
        m_desc.width = dw.max.x - dw.min.x + 1;
        m_desc.height = dw.max.y - dw.min.y + 1;
        m_desc.x = dw.min.x;
        m_desc.y = dw.min.y;
        m_desc.full_x = disp.min.x;
        m_desc.full_y = disp.min.y;
        m_desc.full_width = disp.max.x - disp.min.x + 1;
        m_desc.full_height = disp.max.y - disp.min.y + 1;
        m_desc.floating_point = true;
        std::vector<std::pair<std::string, Imf::PixelType>> channels;
        for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
            channels.emplace_back(it.name(), it.channel().type);
        std::stable_sort(channels.begin(), channels.end(),
                         [](const auto& a, const auto& b) { return channel_rank(a.first) < channel_rank(b.first); });
        for (const auto& [name, type] : channels) {
            m_desc.channel_names.push_back(name);
            m_desc.channel_types.push_back(from_exr(type));
            if (name == "A") m_desc.alpha_channel = m_desc.channels() - 1;
            if (name == "Z") m_desc.z_channel = m_desc.channels() - 1;
        }
        m_desc.attributes.emplace_back("compression", compression_name(h.compression()));
        for (auto it = h.begin(); it != h.end(); ++it)
            if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                m_desc.attributes.emplace_back(it.name(), s->value());
    }

    const ImageDesc& desc() const override { return m_desc; }

    void read(int first, int last, PixelType type, void* out) override {
        if (first < 0 || last > m_desc.channels() || first >= last) throw Error("channel range out of bounds");
        const int n = last - first;
        const size_t pixels = size_t(m_desc.width) * size_t(m_desc.height);
        // OpenEXR converts among half, float and uint; 8/16-bit codes go through float.
        const bool via_float = type == PixelType::UInt8 || type == PixelType::UInt16;
        const PixelType slice_type = via_float ? PixelType::Float : type;
        std::vector<float> scratch(via_float ? pixels * size_t(n) : 0);
        char* base = via_float ? reinterpret_cast<char*>(scratch.data()) : static_cast<char*>(out);
        const size_t sample = pixel_type_bytes(slice_type), x_stride = sample * size_t(n);
        const Imath::Box2i dw = m_file.header().dataWindow();
        Imf::FrameBuffer fb;
        for (int c = first; c < last; ++c)
            fb.insert(m_desc.channel_names[size_t(c)],
                      Imf::Slice::Make(to_exr(slice_type), base + size_t(c - first) * sample, dw, x_stride,
                                       x_stride * size_t(m_desc.width)));
        try {
            m_file.setFrameBuffer(fb);
            m_file.readPixels(dw.min.y, dw.max.y);
        } catch (const std::exception& e) {
            throw Error(e.what());
        }
        if (!via_float) return;
        const float scale = type == PixelType::UInt8 ? 255.f : 65535.f;
        for (size_t i = 0; i < scratch.size(); ++i) {
            const float v = std::isfinite(scratch[i]) ? std::clamp(scratch[i], 0.f, 1.f) : 0.f;
            const auto code = uint32_t(std::lround(v * scale));
            if (type == PixelType::UInt8)
                static_cast<uint8_t*>(out)[i] = uint8_t(code);
            else
                static_cast<uint16_t*>(out)[i] = uint16_t(code);
        }
    }

private:
    Imf::InputFile m_file;
    ImageDesc m_desc;
};

}  // namespace

bool is_exr_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[4] = {};
    in.read(reinterpret_cast<char*>(magic), 4);
    return in.gcount() == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

std::unique_ptr<ImageFileReader> open_exr_file(const std::string& path) {
    use_all_cores();
    try {
        return std::make_unique<ExrReader>(path);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(e.what());
    }
}

std::string exr_compression_error(const std::string& name) {
    ExrCompression unused;
    return parse_compression(name, unused);
}

void write_exr_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)()) {
    use_all_cores();
    if (desc.width <= 0 || desc.height <= 0 || desc.channels() == 0) throw Error("empty image");
    const Imath::Box2i data(Imath::V2i(desc.x, desc.y), Imath::V2i(desc.x + desc.width - 1, desc.y + desc.height - 1));
    const int fw = desc.full_width > 0 ? desc.full_width : desc.width;
    const int fh = desc.full_height > 0 ? desc.full_height : desc.height;
    const Imath::Box2i display(Imath::V2i(desc.full_x, desc.full_y), Imath::V2i(desc.full_x + fw - 1, desc.full_y + fh - 1));
    try {
        Imf::Header header(display, data);
        ExrCompression compression;
        if (const std::string name = desc.attribute("compression"); !name.empty())
            if (const std::string why = parse_compression(name, compression); !why.empty()) throw Error(why);
        header.compression() = compression.codec;
        header.zipCompressionLevel() = compression.level;
        for (const auto& [key, value] : desc.attributes)
            if (key != "compression") header.insert(key, Imf::StringAttribute(value));
        const size_t pixel = desc.pixel_bytes();
        const char* base = static_cast<const char*>(pixels);
        Imf::FrameBuffer fb;
        size_t offset = 0;
        for (int c = 0; c < desc.channels(); ++c) {
            const PixelType t = desc.channel_types[size_t(c)];
            if (t == PixelType::UInt8 || t == PixelType::UInt16) throw Error("EXR has no 8- or 16-bit integer channels");
            header.channels().insert(desc.channel_names[size_t(c)], Imf::Channel(to_exr(t)));
            fb.insert(desc.channel_names[size_t(c)],
                      Imf::Slice::Make(to_exr(t), base + offset, data, pixel, pixel * size_t(desc.width)));
            offset += pixel_type_bytes(t);
        }
        Imf::OutputFile file(path.c_str(), header);
        if (before_pixels) before_pixels();
        file.setFrameBuffer(fb);
        file.writePixels(desc.height);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(e.what());
    }
}

}  // namespace whitted
