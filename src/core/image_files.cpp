// Image files by kind: EXR through OpenEXR in process (image_files_exr.cpp), every other format
// through libwhitted_oiio.so (see image_files.h), found beside the binary holding this code, in
// <prefix>/lib/whitted, or where the build put it; loaded once, on the first such file opened or
// written, and never unloaded.
#include "core/image_files.h"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/data_files.h"
#include "core/error.h"
#include "core/image_files_display.h"
#include "core/image_files_exr.h"
#include "core/log.h"

namespace whitted {

namespace {

namespace fs = std::filesystem;

constexpr const char* kModuleName = "libwhitted_oiio.so";

/// Where the module may be: $WHITTED_IMAGE_MODULE alone when set (a file: no fallback), else in
/// order beside the binary holding this code, <prefix>/lib/whitted (an install; also from the
/// Python module under lib/python3/...), then the path the build wrote it to.
std::vector<std::string> module_candidates() {
    std::vector<std::string> c;
    if (const char* env = std::getenv("WHITTED_IMAGE_MODULE"); env && *env) return {env};
    if (const fs::path dir = whitted_binary_dir(); !dir.empty()) {
        for (const fs::path& p : {dir / kModuleName, dir / "whitted" / kModuleName, dir / "../lib/whitted" / kModuleName,
                                  dir / "../../whitted" / kModuleName, dir / "../../../lib/whitted" / kModuleName})
            c.push_back(p.lexically_normal().string());
    }
#ifdef WHITTED_IMAGE_MODULE_BUILD_PATH
    c.emplace_back(WHITTED_IMAGE_MODULE_BUILD_PATH);
#endif
    return c;
}

std::atomic<const ImageModuleApi*> g_api{nullptr};

const ImageModuleApi& api() {
    if (const ImageModuleApi* a = g_api.load(std::memory_order_acquire)) return *a;
    static std::mutex mutex;
    static std::string failure;
    std::lock_guard lock(mutex);
    if (const ImageModuleApi* a = g_api.load(std::memory_order_acquire)) return *a;
    if (!failure.empty()) throw Error(failure);
    std::vector<std::string> tried;
    std::string last_error;
    for (const std::string& path : module_candidates()) {
        std::error_code ec;
        if (!fs::is_regular_file(path, ec)) {
            tried.push_back(path);
            continue;
        }
        void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char* why = ::dlerror();
            last_error = fmt::format("{}: {}", path, why ? why : "dlopen failed");
            tried.push_back(path);
            continue;
        }
        using Entry = const ImageModuleApi* (*)();
        auto entry = reinterpret_cast<Entry>(::dlsym(handle, "whitted_image_module"));
        const ImageModuleApi* a = entry ? entry() : nullptr;
        if (!a || a->version != kImageModuleVersion) {
            last_error = fmt::format("{}: not a whitted image module of this version", path);
            tried.push_back(path);
            continue;
        }
        log_debug("image files: loaded {}", path);
        g_api.store(a, std::memory_order_release);
        return *a;
    }
    failure = fmt::format("cannot load the image module {} (OpenImageIO): {}", kModuleName,
                          last_error.empty() ? fmt::format("not found (tried {})", fmt::join(tried, ", ")) : last_error);
    throw Error(failure);
}

class ModuleReader final : public ImageFileReader {
public:
    ModuleReader(const ImageModuleApi& api, void* file, ImageDesc desc)
        : m_api(api), m_file(file), m_desc(std::move(desc)) {}
    ~ModuleReader() override { m_api.close(m_file); }
    ModuleReader(const ModuleReader&) = delete;
    ModuleReader& operator=(const ModuleReader&) = delete;
    const ImageDesc& desc() const override { return m_desc; }
    void read(int first, int last, PixelType type, void* out) override {
        std::string error;
        if (!m_api.read(m_file, first, last, type, out, &error)) throw Error(error);
    }

private:
    const ImageModuleApi& m_api;
    void* m_file;
    ImageDesc m_desc;
};

}  // namespace

std::string ImageDesc::attribute(const std::string& name) const {
    for (const auto& [key, value] : attributes)
        if (key == name) return value;
    return {};
}

void ImageDesc::set_attribute(const std::string& name, const std::string& value) {
    for (auto& [key, old] : attributes)
        if (key == name) {
            old = value;
            return;
        }
    attributes.emplace_back(name, value);
}

size_t ImageDesc::pixel_bytes() const {
    size_t n = 0;
    for (PixelType t : channel_types) n += pixel_type_bytes(t);
    return n;
}

std::unique_ptr<ImageFileReader> open_image_file(const std::string& path) {
    if (is_exr_file(path)) return open_exr_file(path);
    const ImageModuleApi& a = api();
    ImageDesc desc;
    std::string error;
    void* file = a.open(path.c_str(), &desc, &error);
    if (!file) throw Error(error);
    return std::make_unique<ModuleReader>(a, file, std::move(desc));
}

void write_image_file(const std::string& path, const ImageDesc& desc, const void* pixels, void (*before_pixels)()) {
    if (desc.format_name == "openexr") return write_exr_file(path, desc, pixels, before_pixels);
    if (desc.format_name == "jpeg") return write_jpeg_file(path, desc, pixels, before_pixels);
    if (desc.format_name == "tiff") return write_tiff_file(path, desc, pixels, before_pixels);
    const ImageModuleApi& a = api();
    std::string error;
    if (!a.write(path.c_str(), &desc, pixels, before_pixels, &error)) throw Error(error);
}

bool image_module_loaded() { return g_api.load() != nullptr; }

}  // namespace whitted
