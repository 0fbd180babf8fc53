#include "importers/gltf_compressed.h"

#include <algorithm>
#include <set>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "importers/gltf_draco.h"
#include "importers/gltf_json.h"
#include "importers/gltf_meshopt.h"

namespace whitted {

namespace {

/// KHR_animation_pointer targets have no `node`, which tinygltf 2.7 requires: -1 stands for none.
bool add_pointer_channel_nodes(nlohmann::json& doc) {
    bool changed = false;
    const auto animations = doc.find("animations");
    if (animations == doc.end() || !animations->is_array()) return false;
    for (nlohmann::json& a : *animations) {
        if (!a.is_object() || !a.contains("channels") || !a["channels"].is_array()) continue;
        for (nlohmann::json& c : a["channels"]) {
            if (!c.is_object() || !c.contains("target") || !c["target"].is_object()) continue;
            nlohmann::json& t = c["target"];
            if (t.contains("node")) continue;
            t["node"] = -1;
            changed = true;
        }
    }
    return changed;
}

}  // namespace

std::optional<std::vector<uint8_t>> prepare_for_tinygltf(std::span<const uint8_t> file, bool binary,
                                                         size_t json_offset, size_t json_size) {
    const char* json = reinterpret_cast<const char*>(file.data()) + json_offset;
    const std::string_view text_in(json, json_size);
    const bool meshopt = text_in.find("EXT_meshopt_compression") != std::string_view::npos;
    const bool draco = text_in.find("KHR_draco_mesh_compression") != std::string_view::npos;
    const bool pointer = text_in.find("KHR_animation_pointer") != std::string_view::npos;
    if (!meshopt && !draco && !pointer) return std::nullopt;
    nlohmann::json doc = nlohmann::json::parse(json, json + json_size, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return std::nullopt;  // tinygltf reports the JSON error
    bool changed = meshopt && add_meshopt_fallback_uris(doc, binary);
    changed = (draco && detach_draco_indices(doc)) || changed;
    changed = (pointer && add_pointer_channel_nodes(doc)) || changed;
    if (!changed) return std::nullopt;

    std::string text = doc.dump();
    if (!binary) return std::vector<uint8_t>(text.begin(), text.end());
    while (text.size() % 4) text += ' ';
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) {
        for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
    };
    const size_t rest = json_offset + json_size;  // the chunks after JSON, unchanged
    u32(0x46546C67);                              // "glTF"
    u32(2);
    u32(uint32_t(12 + 8 + text.size() + (file.size() - rest)));
    u32(uint32_t(text.size()));
    u32(0x4E4F534A);  // "JSON"
    out.insert(out.end(), text.begin(), text.end());
    out.insert(out.end(), file.begin() + std::ptrdiff_t(rest), file.end());
    return out;
}

std::vector<CompressedPrimitive> meshopt_primitives(const tinygltf::Model& model) {
    std::vector<CompressedPrimitive> records;
    const std::string name = "EXT_meshopt_compression";
    const auto compressed = [&](const tinygltf::BufferView& v) { return v.extensions.count(name) != 0; };
    if (std::none_of(model.bufferViews.begin(), model.bufferViews.end(), compressed)) return records;
    for (size_t m = 0; m < model.meshes.size(); ++m)
        for (size_t i = 0; i < model.meshes[m].primitives.size(); ++i) {
            const tinygltf::Primitive& p = model.meshes[m].primitives[i];
            std::set<int> views;
            auto add = [&](int accessor) {
                if (accessor >= 0 && size_t(accessor) < model.accessors.size()) views.insert(model.accessors[size_t(accessor)].bufferView);
            };
            add(p.indices);
            for (const auto& entry : p.attributes) add(entry.second);
            CompressedPrimitive r{fmt::format("/meshes/{}/primitives/{}", m, i), "meshopt", 0, 0};
            for (const int v : views) {
                if (v < 0 || size_t(v) >= model.bufferViews.size()) continue;
                const tinygltf::Value* ext =
                    gltf::find_extension(model.bufferViews[size_t(v)].extensions, "EXT_meshopt_compression");
                int length = 0, count = 0, stride = 0;
                if (ext == nullptr || !gltf::as_int(gltf::find_member(ext, "byteLength"), length) ||
                    !gltf::as_int(gltf::find_member(ext, "count"), count) ||
                    !gltf::as_int(gltf::find_member(ext, "byteStride"), stride))
                    continue;
                r.compressed_bytes += uint64_t(length);
                r.decoded_bytes += uint64_t(count) * uint64_t(stride);
            }
            if (r.compressed_bytes > 0) records.push_back(std::move(r));
        }
    return records;
}

}  // namespace whitted
