// A binary glTF written by hand, for the generated benchmark scenes (generated_skin.cpp,
// material_samples.cpp): a buffer built view by view, the JSON around it, and the GLB container.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace whitted::app {

/// The binary buffer, built view by view (each 4-byte aligned), and the JSON of its views and accessors.
struct GlbLayout {
    std::vector<uint8_t> bin;
    std::vector<std::string> views, accessors;

    /// Appends `data` as a view (with `target` when non-zero) and one accessor of `count` elements
    /// over it; returns the accessor index.
    template <typename T>
    int add(const std::vector<T>& data, int component, const char* type, size_t count, int target,
            const std::string& extra = "") {
        const size_t offset = bin.size();
        const size_t length = data.size() * sizeof(T);
        bin.resize(offset + length);
        std::memcpy(bin.data() + offset, data.data(), length);
        bin.resize((bin.size() + 3) & ~size_t(3), 0);
        views.push_back(fmt::format("{{\"buffer\": 0, \"byteOffset\": {}, \"byteLength\": {}{}}}", offset, length,
                                    target ? fmt::format(", \"target\": {}", target) : ""));
        accessors.push_back(fmt::format("{{\"bufferView\": {}, \"componentType\": {}, \"count\": {}, \"type\": \"{}\"{}}}",
                                        views.size() - 1, component, count, type, extra));
        return int(accessors.size() - 1);
    }
};

/// The items joined by `separator`.
std::string join(const std::vector<std::string>& items, const char* separator);

/// Writes `json` and `bin` as a GLB (glTF 2.0 section 4.4: the JSON chunk padded with spaces, the
/// BIN chunk with zeros) and returns its size; throws whitted::Error naming `what` when it does not
/// fit a GLB or cannot be written.
size_t write_glb(const std::filesystem::path& path, const std::string& json, const std::vector<uint8_t>& bin,
                 const char* what);

}  // namespace whitted::app
