// Image files read and written through OpenImageIO, which is loaded only when an image file is
// first opened.
//
// Debian's libOpenImageIO pulls in about 260 shared libraries (OpenCV, GDAL, DCMTK, OpenVDB,
// ffmpeg, ...): linked into whitted, it cost every process ~0.2 s and ~130 MB before main(),
// including `whitted --help` and renders that never touch an image file (docs/performance.md,
// "Fixed cost of a run"). So the OIIO calls live in a small module of ours, libwhitted_oiio.so
// (image_files_oiio.cpp), that this layer dlopen()s on first use. The types here are plain data:
// neither side needs the other's headers beyond this one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// A channel's sample type in a file or in a buffer.
enum class PixelType : uint8_t { UInt8, UInt16, UInt32, Half, Float };

constexpr size_t pixel_type_bytes(PixelType t) {
    switch (t) {
        case PixelType::UInt8: return 1;
        case PixelType::UInt16:
        case PixelType::Half: return 2;
        case PixelType::UInt32:
        case PixelType::Float: return 4;
    }
    return 0;
}

/// What a file holds (or is to hold): the first subimage's windows, channels and string
/// attributes. Mirrors the parts of OIIO::ImageSpec whitted uses.
struct ImageDesc {
    int width = 0, height = 0, depth = 1;        ///< data window size
    int x = 0, y = 0;                            ///< data window origin
    int full_x = 0, full_y = 0;                  ///< display window origin
    int full_width = 0, full_height = 0;         ///< display window size (0 on write: the data window)
    std::vector<std::string> channel_names;      ///< one per channel
    std::vector<PixelType> channel_types;        ///< one per channel (read: as stored, nearest PixelType)
    int alpha_channel = -1, z_channel = -1;
    bool floating_point = false;                 ///< read: the file stores floating-point samples
    std::string format_name;                     ///< read: OIIO's name ("openexr", "png", ...); write: the writer
    /// String attributes: on write the file's metadata ("compression", "Software", EXR header
    /// entries, PNG text); on read every string attribute OIIO reports ("oiio:ColorSpace", ...).
    std::vector<std::pair<std::string, std::string>> attributes;

    int channels() const { return int(channel_names.size()); }
    /// The value of a string attribute, or "" when absent.
    std::string attribute(const std::string& name) const;
    /// Sets a string attribute: replaced when present, else appended.
    void set_attribute(const std::string& name, const std::string& value);
    /// Bytes of one pixel with every channel in its own type (the layout write_image_file takes).
    size_t pixel_bytes() const;
};

/// An open image file. Errors throw whitted::Error with the library's message (one line), to
/// which callers add their context (the file, what it was for).
class ImageFileReader {
public:
    virtual ~ImageFileReader() = default;
    virtual const ImageDesc& desc() const = 0;
    /// Channels [first, last) of every pixel of the first subimage, converted to `type`,
    /// interleaved, into `out` (width * height * (last - first) samples).
    virtual void read(int first, int last, PixelType type, void* out) = 0;
};

/// Opens `path` for reading (any format OIIO reads). Throws whitted::Error with the library's
/// reason ("" when it gives none) when the file cannot be opened; the message is the bare reason.
std::unique_ptr<ImageFileReader> open_image_file(const std::string& path);

/// Writes `pixels` (every pixel's channels in their own types, desc.pixel_bytes() per pixel,
/// rows top to bottom) to `path` with the writer `desc.format_name` ("openexr", "png", "jpeg",
/// "tiff"). Throws whitted::Error with the bare reason on failure; the caller owns atomicity.
/// `before_pixels` (may be null) runs once the file is open and before the pixels go out.
void write_image_file(const std::string& path, const ImageDesc& desc, const void* pixels,
                      void (*before_pixels)() = nullptr);

/// Whether the image module is loaded in this process (tests: a run that reads and writes no
/// image file never loads it).
bool image_module_loaded();

// ---- the module's side ------------------------------------------------------------------------

/// The entry points of libwhitted_oiio.so, found by dlsym("whitted_image_module"). Errors come
/// back as text in `error` (no exceptions cross the module boundary).
struct ImageModuleApi {
    int version;  ///< kImageModuleVersion of the module's build
    void* (*open)(const char* path, ImageDesc* desc, std::string* error);
    bool (*read)(void* file, int first, int last, PixelType type, void* out, std::string* error);
    void (*close)(void* file);
    bool (*write)(const char* path, const ImageDesc* desc, const void* pixels, void (*before_pixels)(),
                  std::string* error);
};
inline constexpr int kImageModuleVersion = 1;

}  // namespace whitted

extern "C" {
/// Defined by libwhitted_oiio.so.
const whitted::ImageModuleApi* whitted_image_module();
}
