// Output: scene-linear film -> OpenColorIO display transform -> OpenImageIO file.
//
// The pipeline for display-referred files (PNG/JPEG/TIFF) is
//     scene-linear Rec.709 -> OCIO DisplayViewTransform -> sanitize + clamp [0,1] -> quantize
// while EXR stores the scene-linear values untouched (plus AOVs). Every file is written to a
// temporary name in the destination directory and renamed, so a reader sees a complete file
// or none. See docs/color.md.

#include "output/image_output.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <thread>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <string_view>
#include <system_error>
#include <utility>

#include <unistd.h>

#include <Imath/half.h>
#include <OpenColorIO/OpenColorIO.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include "core/data_files.h"
#include "core/error.h"
#include "core/image_files.h"
#include "core/image_files_display.h"
#include "core/image_files_exr.h"
#include "core/log.h"
#include "output/png_encoder.h"
namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace whitted {

namespace {

// Comma-separated list of names for error messages ("a, b, c").
std::string join_names(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

bool file_exists(const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec);
}

}  // namespace

// ---- bundled config --------------------------------------------------------------------------

std::string bundled_ocio_config() {
    try {
        return data_file("ocio/config.ocio");
    } catch (const Error& e) {
        throw Error(fmt::format("bundled OCIO config: {}", e.what()));
    }
}

// ---- DisplayTransform ------------------------------------------------------------------------

struct DisplayTransform::Impl {
    std::string config_path;
    std::string display;
    std::string view;
    OCIO::ConstConfigRcPtr config;
    OCIO::ConstCPUProcessorRcPtr cpu;  ///< F32 RGB in, F32 RGB out; apply() is const and thread-safe
    std::once_flag table_built;           ///< the 8-bit code table, built on first use
    std::optional<CodeTable> table;
};

DisplayTransform::DisplayTransform(const ColorSettings& settings) : m_impl(std::make_unique<Impl>()) {
    Impl& impl = *m_impl;

    // Resolve the config: explicit setting, then $OCIO (the ecosystem convention), then ours.
    std::string source;
    if (!settings.config.empty()) {
        impl.config_path = settings.config;
        source = "--ocio-config";
    } else if (const char* env = std::getenv("OCIO"); env != nullptr && env[0] != '\0') {
        impl.config_path = env;
        source = "$OCIO";
    } else {
        impl.config_path = bundled_ocio_config();
        source = "bundled";
    }
    if (!file_exists(impl.config_path))
        throw Error(fmt::format("OCIO config '{}' (from {}) not found", impl.config_path, source));

    try {
        impl.config = OCIO::Config::CreateFromFile(impl.config_path.c_str());
        impl.config->validate();
    } catch (const OCIO::Exception& e) {
        throw Error(fmt::format("OCIO config '{}' (from {}): {}", impl.config_path, source, e.what()));
    }
    const OCIO::Config& config = *impl.config;

    // Display: the requested one, or the config's default.
    std::vector<std::string> displays;
    for (int i = 0; i < config.getNumDisplays(); ++i) displays.emplace_back(config.getDisplay(i));
    impl.display = settings.display.empty() ? std::string(config.getDefaultDisplay()) : settings.display;
    if (std::find(displays.begin(), displays.end(), impl.display) == displays.end())
        throw Error(fmt::format("unknown OCIO display '{}' in config '{}' (valid displays: {})", impl.display,
                                impl.config_path, join_names(displays)));

    // View: the requested one, or the display's default when empty.
    std::vector<std::string> views;
    for (int i = 0; i < config.getNumViews(impl.display.c_str()); ++i)
        views.emplace_back(config.getView(impl.display.c_str(), i));
    impl.view = settings.view.empty() ? std::string(config.getDefaultView(impl.display.c_str())) : settings.view;
    if (std::find(views.begin(), views.end(), impl.view) == views.end())
        throw Error(fmt::format("unknown OCIO view '{}' for display '{}' in config '{}' (valid views: {})", impl.view,
                                impl.display, impl.config_path, join_names(views)));

    // scene_linear -> (display, view), compiled once into a float CPU processor.
    try {
        OCIO::DisplayViewTransformRcPtr transform = OCIO::DisplayViewTransform::Create();
        transform->setSrc(OCIO::ROLE_SCENE_LINEAR);
        transform->setDisplay(impl.display.c_str());
        transform->setView(impl.view.c_str());
        impl.cpu = config.getProcessor(transform)->getDefaultCPUProcessor();
    } catch (const OCIO::Exception& e) {
        throw Error(fmt::format("OCIO config '{}': cannot build display '{}' view '{}': {}", impl.config_path,
                                impl.display, impl.view, e.what()));
    }
    log_debug("OCIO: config '{}' ({}), display '{}', view '{}'", impl.config_path, source, impl.display, impl.view);
}

DisplayTransform::~DisplayTransform() = default;
DisplayTransform::DisplayTransform(DisplayTransform&&) noexcept = default;

void DisplayTransform::apply(float* rgb, size_t pixel_count) const {
    // OCIO processes packed RGBA floats in place, while packed RGB goes through a scratch line it
    // allocates per call: copy bounded runs into RGBA on the stack instead, on all cores for
    // large inputs (each pixel on its own: the same values for any split).
    constexpr size_t kRun = 1024;
    auto run = [&](size_t first, size_t n) {
        std::array<float, 4 * kRun> rgba;
        for (size_t i = 0; i < n; ++i) {
            std::memcpy(&rgba[4 * i], rgb + 3 * (first + i), 3 * sizeof(float));
            rgba[4 * i + 3] = 1.f;
        }
        OCIO::PackedImageDesc desc(rgba.data(), long(n), 1, 4);
        m_impl->cpu->apply(desc);
        for (size_t i = 0; i < n; ++i) std::memcpy(rgb + 3 * (first + i), &rgba[4 * i], 3 * sizeof(float));
    };
    const size_t runs = (pixel_count + kRun - 1) / kRun;
    auto range = [&](size_t r0, size_t r1) {
        for (size_t r = r0; r < r1; ++r) run(r * kRun, std::min(kRun, pixel_count - r * kRun));
    };
    if (runs <= 16) return range(0, runs);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, runs, 4), [&](const tbb::blocked_range<size_t>& r) { range(r.begin(), r.end()); });
}

Color DisplayTransform::apply(Color c) const {
    std::array<float, 3> p{c.x, c.y, c.z};
    m_impl->cpu->applyRGB(p.data());
    return {p[0], p[1], p[2]};
}

const CodeTable* DisplayTransform::code_table(int bits) const {
    if (bits != 8) return nullptr;
    std::call_once(m_impl->table_built, [&] {
        if (m_impl->cpu->hasChannelCrosstalk()) return;
        m_impl->table = CodeTable::build([this](float* rgb, size_t n) { apply(rgb, n); }, 8);
        log_debug("OCIO: 8-bit code table {}", m_impl->table ? "in use" : "refused (codes from the transform)");
    });
    return m_impl->table ? &*m_impl->table : nullptr;
}

const std::string& DisplayTransform::config_path() const { return m_impl->config_path; }
const std::string& DisplayTransform::display() const { return m_impl->display; }
const std::string& DisplayTransform::view() const { return m_impl->view; }

// ---- image files -----------------------------------------------------------------------------

void display_codes(std::span<const Color> pixels, const DisplayTransform& transform, int bits, std::span<uint8_t> out) {
    if (bits != 8 && bits != 16) throw Error(fmt::format("unsupported bit depth {} (use 8 or 16)", bits));
    const size_t bytes_per_code = bits == 16 ? 2 : 1;
    if (out.size() != pixels.size() * 3 * bytes_per_code)
        throw Error(fmt::format("display_codes: {} bytes for {} pixels of {} bits", out.size(), pixels.size(), bits));
    // Sanitize before the transform: NaN -> 0 and +-inf -> +-65504 (half max), so that
    // transforms mixing channels (the ACES matrices) never turn one bad channel into NaN.
    const float scale = bits == 16 ? 65535.f : 255.f;
    auto put = [&](size_t at, uint32_t code) {
        if (bits == 16) {
            const auto q = static_cast<uint16_t>(code);
            std::memcpy(&out[2 * at], &q, 2);
        } else {
            out[at] = static_cast<uint8_t>(code);
        }
    };
    // Chunks of pixels on all cores (every pixel on its own: the codes are the same for any split).
    constexpr size_t kChunk = 16384;
    const size_t chunks = (pixels.size() + kChunk - 1) / kChunk;
    if (const CodeTable* table = transform.code_table(bits)) {
        // A per-channel transform: each code looked up among the transform's own thresholds.
        tbb::parallel_for(size_t(0), chunks, [&](size_t chunk) {
            const size_t first = chunk * kChunk, end = std::min(first + kChunk, pixels.size());
            for (size_t i = first; i < end; ++i)
                for (int c = 0; c < 3; ++c) put(3 * i + size_t(c), table->code(c, sanitise_linear(pixels[i][c])));
        });
        return;
    }
    tbb::parallel_for(size_t(0), chunks, [&](size_t chunk) {
        const size_t first = chunk * kChunk, n = std::min(kChunk, pixels.size() - first);
        std::vector<float> rgb(n * 3);
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = sanitise_linear(pixels[first + i][c]);
        transform.apply(rgb.data(), n);
        // After the transform (OCIO does not clamp): NaN -> 0, clamped to [0, 1], rounded.
        for (size_t i = 0; i < rgb.size(); ++i) put(3 * first + i, display_code(rgb[i], scale));
    });
}

namespace {

enum class FileKind { Exr, Png, Jpeg, Tiff };

constexpr std::string_view kSupportedExtensions = ".exr, .png, .jpg, .jpeg, .tif, .tiff";

/// The file kind for an extension (case-insensitive, with the dot), or nothing.
std::optional<FileKind> kind_from_extension(std::string ext) {
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    if (ext == ".exr") return FileKind::Exr;
    if (ext == ".png") return FileKind::Png;
    if (ext == ".jpg" || ext == ".jpeg") return FileKind::Jpeg;
    if (ext == ".tif" || ext == ".tiff") return FileKind::Tiff;
    return std::nullopt;
}

/// OIIO format name, so the writer never depends on how OIIO parses the temporary name.
const char* oiio_format_name(FileKind kind) {
    switch (kind) {
        case FileKind::Exr: return "openexr";
        case FileKind::Png: return "png";
        case FileKind::Jpeg: return "jpeg";
        case FileKind::Tiff: return "tiff";
    }
    return "";
}

/// Checks that the film's buffers match its window; a mismatch is a caller bug worth a clear error.
void validate_film(const Film& film, const std::string& path) {
    const PixelWindow& w = film.window;
    if (w.width() <= 0 || w.height() <= 0)
        throw Error(fmt::format("{}: empty film window [{}, {}) x [{}, {})", path, w.x0, w.x1, w.y0, w.y1));
    if (w.x0 < 0 || w.y0 < 0 || w.x1 > film.full_width || w.y1 > film.full_height)
        throw Error(fmt::format("{}: film window [{}, {}) x [{}, {}) outside the {}x{} image", path, w.x0, w.x1, w.y0,
                                w.y1, film.full_width, film.full_height));
    const size_t n = size_t(w.width()) * size_t(w.height());
    auto check = [&](bool wanted, size_t size, const char* name) {
        if (wanted && size != n)
            throw Error(fmt::format("{}: film {} buffer has {} pixels, window has {}", path, name, size, n));
    };
    check(true, film.beauty.size(), "beauty");
    check(film.aovs.depth, film.depth.size(), "depth");
    check(film.aovs.normal, film.normal.size(), "normal");
    check(film.aovs.albedo, film.albedo.size(), "albedo");
    check(film.aovs.prim_id, film.prim_id.size(), "prim_id");
    check(film.aovs.inst_id, film.inst_id.size(), "inst_id");
    check(film.aovs.aa_samples, film.aa_samples.size(), "aa_samples");
}

/// One image ready for a writer: what it holds and its pixels, every channel in its own type.
struct EncodedImage {
    ImageDesc desc;
    std::vector<unsigned char> bytes;
};

/// Stores the raw bytes of `value` at `out` (native layout for per-channel EXR formats) and
/// returns the byte after them.
template <typename T>
unsigned char* put_bytes(unsigned char* out, const T& value) {
    std::memcpy(out, &value, sizeof(T));
    return out + sizeof(T);
}

/// Scene-linear EXR: beauty (half or float) + AOVs, data window = film window inside the
/// full_width x full_height display window.
EncodedImage encode_exr(const Film& film, const OutputSettings& settings) {
    const PixelType beauty_type = settings.exr_half ? PixelType::Half : PixelType::Float;
    EncodedImage image;
    ImageDesc& desc = image.desc;
    desc.format_name = "openexr";
    desc.width = film.width();
    desc.height = film.height();

    // Channel layout; AOVs are data, so they stay float (ids: 32-bit unsigned) in either mode.
    auto add = [&](std::initializer_list<const char*> channel_names, PixelType type) {
        for (const char* name : channel_names) {
            desc.channel_names.emplace_back(name);
            desc.channel_types.push_back(type);
        }
    };
    add({"R", "G", "B"}, beauty_type);
    if (film.aovs.depth) add({"Z"}, PixelType::Float);
    if (film.aovs.normal) add({"N.X", "N.Y", "N.Z"}, PixelType::Float);
    if (film.aovs.albedo) add({"albedo.R", "albedo.G", "albedo.B"}, PixelType::Float);
    if (film.aovs.prim_id) add({"primId"}, PixelType::UInt32);
    if (film.aovs.inst_id) add({"instId"}, PixelType::UInt32);
    if (film.aovs.aa_samples) add({"aa.samples"}, PixelType::Float);
    desc.alpha_channel = -1;
    desc.z_channel = film.aovs.depth ? 3 : -1;

    // Crop: data window inside the display window.
    desc.x = film.window.x0;
    desc.y = film.window.y0;
    desc.full_x = 0;
    desc.full_y = 0;
    desc.full_width = film.full_width;
    desc.full_height = film.full_height;
    desc.attributes.emplace_back("compression", settings.exr_compression);

    // Pack the pixels in the file's native per-channel layout, so ids stay exact 32-bit values.
    const size_t n = film.beauty.size();
    const size_t pixel_bytes = desc.pixel_bytes();
    image.bytes.resize(n * pixel_bytes);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            unsigned char* p = image.bytes.data() + i * pixel_bytes;
            const Color& c = film.beauty[i];
            for (float v : {c.x, c.y, c.z}) {
                if (settings.exr_half)
                    p = put_bytes(p, Imath::half(v));
                else
                    p = put_bytes(p, v);
            }
            if (film.aovs.depth) p = put_bytes(p, film.depth[i]);
            if (film.aovs.normal) {
                const Vec3f& v = film.normal[i];
                for (float f : {v.x, v.y, v.z}) p = put_bytes(p, f);
            }
            if (film.aovs.albedo) {
                const Color& a = film.albedo[i];
                for (float f : {a.x, a.y, a.z}) p = put_bytes(p, f);
            }
            if (film.aovs.prim_id) p = put_bytes(p, film.prim_id[i]);
            if (film.aovs.inst_id) p = put_bytes(p, film.inst_id[i]);
            if (film.aovs.aa_samples) p = put_bytes(p, film.aa_samples[i]);
            if (i + 1 == range.end()) RT_CHECK(p == image.bytes.data() + (i + 1) * pixel_bytes);  // layout == desc
        }
    });
    return image;
}

/// Display-referred 8/16-bit image of the film window (the crop origin is not stored: PNG and
/// JPEG have no data window, so these files hold exactly the rendered pixels).
EncodedImage encode_display(const Film& film, FileKind kind, const OutputSettings& settings,
                            const std::string& path) {
    const int bits = settings.bits != 0 ? settings.bits : (kind == FileKind::Tiff ? 16 : 8);
    if (bits != 8 && bits != 16)
        throw Error(fmt::format("{}: unsupported bit depth {} (use 8 or 16)", path, settings.bits));
    if (bits == 16 && kind == FileKind::Jpeg) throw Error(fmt::format("{}: JPEG supports only 8 bits", path));

    EncodedImage image;
    ImageDesc& desc = image.desc;
    desc.format_name = oiio_format_name(kind);
    desc.width = film.width();
    desc.height = film.height();
    desc.channel_names = {"R", "G", "B"};
    desc.channel_types.assign(3, bits == 16 ? PixelType::UInt16 : PixelType::UInt8);
    image.bytes.resize(film.beauty.size() * 3 * (bits == 16 ? 2 : 1));
    std::optional<DisplayTransform> transform;
    try {
        transform.emplace(settings.color);
        display_codes(film.beauty, *transform, bits, image.bytes);
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}", path, e.what()));
    }

    // zip = Deflate level 1, chosen by measurement on 1920x1080 (docs/measurements/performance.md).
    if (kind == FileKind::Tiff) desc.attributes.emplace_back("compression", settings.tiff_compression);
    desc.attributes.emplace_back("whitted:display", transform->display());
    desc.attributes.emplace_back("whitted:view", transform->view());
    return image;
}

/// The temporary file of the write in progress as a plain C string, so that a signal handler can
/// remove it (remove_partial_output()); one write at a time is tracked (the CLI writes one).
char g_partial_path[4096];
std::atomic<bool> g_partial_active{false};

/// Removes a temporary file when it goes out of scope, unless released (after the rename).
class TempFileGuard {
public:
    explicit TempFileGuard(fs::path path) : m_path(std::move(path)) {
        const std::string& s = m_path.native();
        bool expected = false;
        if (s.size() < sizeof(g_partial_path) && g_partial_active.compare_exchange_strong(expected, true)) {
            // Published before the file exists; unlink of a missing file is harmless.
            std::memcpy(g_partial_path, s.c_str(), s.size() + 1);
            m_tracked = true;
        }
    }
    ~TempFileGuard() {
        if (m_active) {
            std::error_code ignored;
            fs::remove(m_path, ignored);
        }
        untrack();
    }
    TempFileGuard(const TempFileGuard&) = delete;
    TempFileGuard& operator=(const TempFileGuard&) = delete;
    const fs::path& path() const { return m_path; }
    void release() {
        m_active = false;
        untrack();
    }

private:
    void untrack() {
        if (m_tracked) g_partial_active.store(false);
        m_tracked = false;
    }

    fs::path m_path;
    bool m_active = true;
    bool m_tracked = false;  ///< registered in g_partial_path
};

/// Test hook: holds the half-written temporary file for a while, so the CLI tests can interrupt
/// a write in progress (tests/cli/test_cli.cpp). Unset in normal use.
void test_write_delay() {
    if (const char* delay = std::getenv("WHITTED_TEST_WRITE_DELAY_MS"))
        std::this_thread::sleep_for(std::chrono::milliseconds(std::clamp(std::atol(delay), 0L, 60000L)));
}

/// Writes `image` to "<dir>/.<stem>.tmp-<pid><ext>" and renames it to `path`; on any failure
/// (including exceptions) the temporary file is removed; errors are whitted::Error("<path>: <reason>").
void write_atomically(const EncodedImage& image, const fs::path& path) {
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("{}: directory '{}' does not exist", path.string(), dir.string()));
    auto fail = [&](const std::string& reason) { return Error(fmt::format("{}: {}", path.string(), reason)); };

    // The real extension stays last so that every tool recognises the temporary file's format.
    TempFileGuard temp(dir / fmt::format(".{}.tmp-{}{}", path.stem().string(), long(::getpid()),
                                         path.extension().string()));
    if (image.desc.format_name == "png") {
        // PNG is encoded in house (png_encoder.h): OIIO is not even loaded.
        const int bits = image.desc.channel_types.front() == PixelType::UInt16 ? 16 : 8;
        std::vector<uint8_t> png;
        try {
            png = encode_png(image.bytes, image.desc.width, image.desc.height, bits, image.desc.attributes);
        } catch (const Error& e) {
            throw fail(e.what());
        }
        std::FILE* f = std::fopen(temp.path().c_str(), "wb");
        if (!f) throw fail(fmt::format("cannot create '{}': {}", temp.path().string(), std::strerror(errno)));
        test_write_delay();
        const bool written = std::fwrite(png.data(), 1, png.size(), f) == png.size();
        const int saved = errno;
        if (std::fclose(f) != 0 || !written)
            throw fail(fmt::format("cannot write '{}': {}", temp.path().string(), std::strerror(written ? errno : saved)));
    } else {
        try {
            write_image_file(temp.path().string(), image.desc, image.bytes.data(), test_write_delay);
        } catch (const Error& e) {
            throw fail(e.what());
        }
    }
    fs::rename(temp.path(), path, ec);
    if (ec) throw fail(fmt::format("cannot rename '{}': {}", temp.path().string(), ec.message()));
    temp.release();
}

}  // namespace

// Async-signal-safe: unlink only.
void remove_partial_output() noexcept {
    if (g_partial_active.load()) ::unlink(g_partial_path);
}

void apply_scene_output_settings(const SceneRenderSettings& s, const std::string& scene_path, std::string& output_path,
                                 OutputSettings& settings, const SettingGiven& given) {
    auto from_file = [&](std::string_view key) { return !given || !given(key); };
    if (s.view && from_file("view")) settings.color.view = *s.view;
    if (s.display && from_file("display")) settings.color.display = *s.display;
    if (s.output && from_file("output")) {
        const fs::path out(*s.output);
        output_path = out.is_absolute() ? out.string() : (fs::path(scene_path).parent_path() / out).string();
    }
}

void write_image(const Film& film, const std::string& path, const OutputSettings& settings) {
    const fs::path file(path);
    const std::optional<FileKind> kind = kind_from_extension(file.extension().string());
    if (!kind)
        throw Error(fmt::format("{}: unsupported image extension '{}' (supported: {})", path,
                                file.extension().string(), kSupportedExtensions));
    if (*kind == FileKind::Exr)
        if (const std::string why = exr_compression_error(settings.exr_compression); !why.empty())
            throw Error(fmt::format("{}: {}", path, why));
    if (*kind == FileKind::Tiff)
        if (const std::string why = tiff_compression_error(settings.tiff_compression); !why.empty())
            throw Error(fmt::format("{}: {}", path, why));
    validate_film(film, path);

    EncodedImage image =
        *kind == FileKind::Exr ? encode_exr(film, settings) : encode_display(film, *kind, settings, path);
    // Metadata as string attributes: EXR header attributes, PNG text chunks, TIFF/JPEG where
    // the format has a place for them (OIIO drops the rest). The caller's keys win.
    image.desc.set_attribute("Software", "whitted " WHITTED_VERSION);
    for (const auto& [key, value] : settings.metadata) image.desc.set_attribute(key, value);

    write_atomically(image, file);
    log_debug("wrote {} ({}x{}, {} channels)", path, image.desc.width, image.desc.height, image.desc.channels());
}

namespace {

/// open_image_file with the path in its errors ("<path>: <prefix><reason>").
std::unique_ptr<ImageFileReader> open_for_reading(const std::string& path, const char* prefix) {
    try {
        return open_image_file(path);
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}{}", path, prefix, e.what()));
    }
}

}  // namespace

std::vector<float> read_image_rgb(const std::string& path, int& width, int& height) {
    std::unique_ptr<ImageFileReader> in = open_for_reading(path, "");
    const ImageDesc& spec = in->desc();
    width = spec.width;
    height = spec.height;
    const size_t n = size_t(width) * size_t(height);

    // The first three channels; a one- or two-channel (grey, grey + alpha) image repeats grey.
    const int channels = std::min(spec.channels(), 3);
    std::vector<float> read(n * size_t(channels));
    try {
        in->read(0, channels, PixelType::Float, read.data());
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}", path, e.what()));
    }
    if (channels == 3) return read;
    std::vector<float> rgb(n * 3);
    for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < 3; ++c) rgb[3 * i + c] = read[i * size_t(channels)];
    return rgb;
}

Film read_film(const std::string& path, std::map<std::string, std::string>* metadata, PixelType* beauty_type) {
    std::unique_ptr<ImageFileReader> in = open_for_reading(path, "cannot read: ");
    const ImageDesc& spec = in->desc();
    if (spec.format_name != "openexr") throw Error(fmt::format("{}: not an EXR file", path));
    auto channel = [&](std::string_view name) {
        for (int c = 0; c < spec.channels(); ++c)
            if (spec.channel_names[size_t(c)] == name) return c;
        return -1;
    };
    const int r = channel("R"), g = channel("G"), b = channel("B");
    if (r < 0 || g < 0 || b < 0) throw Error(fmt::format("{}: no R, G, B channels", path));
    if (beauty_type) *beauty_type = spec.channel_types.empty() ? PixelType::Float : spec.channel_types[size_t(r)];
    AovSet aovs;
    aovs.depth = channel("Z") >= 0;
    aovs.normal = channel("N.X") >= 0;
    aovs.albedo = channel("albedo.R") >= 0;
    aovs.prim_id = channel("primId") >= 0;
    aovs.inst_id = channel("instId") >= 0;
    aovs.aa_samples = channel("aa.samples") >= 0;
    const PixelWindow window{spec.x, spec.y, spec.x + spec.width, spec.y + spec.height};
    if (spec.full_x != 0 || spec.full_y != 0 || window.x0 < 0 || window.y0 < 0 || window.x1 > spec.full_width ||
        window.y1 > spec.full_height || spec.width <= 0 || spec.height <= 0)
        throw Error(fmt::format("{}: data window {},{},{},{} is not inside the {}x{} display window", path, window.x0,
                                window.y0, window.x1, window.y1, spec.full_width, spec.full_height));
    Film film(spec.full_width, spec.full_height, window, aovs);
    const size_t n = film.beauty.size();
    // Channel by channel as float; the ids as 32-bit unsigned, exactly.
    auto read_channel = [&](int c, PixelType type, void* out) {
        try {
            in->read(c, c + 1, type, out);
        } catch (const Error& e) {
            throw Error(fmt::format("{}: {}", path, e.what()));
        }
    };
    std::vector<float> plane(n);
    auto read_into = [&](int c, auto&& store) {
        read_channel(c, PixelType::Float, plane.data());
        for (size_t i = 0; i < n; ++i) store(i, plane[i]);
    };
    read_into(r, [&](size_t i, float v) { film.beauty[i].x = v; });
    read_into(g, [&](size_t i, float v) { film.beauty[i].y = v; });
    read_into(b, [&](size_t i, float v) { film.beauty[i].z = v; });
    if (aovs.depth) read_into(channel("Z"), [&](size_t i, float v) { film.depth[i] = v; });
    if (aovs.normal) {
        read_into(channel("N.X"), [&](size_t i, float v) { film.normal[i].x = v; });
        read_into(channel("N.Y"), [&](size_t i, float v) { film.normal[i].y = v; });
        read_into(channel("N.Z"), [&](size_t i, float v) { film.normal[i].z = v; });
    }
    if (aovs.albedo) {
        read_into(channel("albedo.R"), [&](size_t i, float v) { film.albedo[i].x = v; });
        read_into(channel("albedo.G"), [&](size_t i, float v) { film.albedo[i].y = v; });
        read_into(channel("albedo.B"), [&](size_t i, float v) { film.albedo[i].z = v; });
    }
    if (aovs.prim_id) read_channel(channel("primId"), PixelType::UInt32, film.prim_id.data());
    if (aovs.inst_id) read_channel(channel("instId"), PixelType::UInt32, film.inst_id.data());
    if (aovs.aa_samples) read_into(channel("aa.samples"), [&](size_t i, float v) { film.aa_samples[i] = v; });
    if (metadata) {
        metadata->clear();
        for (const auto& [key, value] : spec.attributes) (*metadata)[key] = value;
    }
    return film;
}

}  // namespace whitted
