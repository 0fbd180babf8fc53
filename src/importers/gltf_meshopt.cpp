#include "importers/gltf_meshopt.h"

#include <cstring>

#include <fmt/format.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "importers/gltf_json.h"
#include "core/error.h"

namespace whitted {

namespace {

constexpr const char* kExt = "EXT_meshopt_compression";
constexpr const char* kMarker = "whitted-meshopt-fallback-";

[[noreturn]] void fail(const std::string& path, const std::string& pointer, const std::string& message) {
    FileLoc loc;
    loc.file = path;
    loc.pointer = pointer;
    throw Error(loc, message);
}

}  // namespace

std::string meshopt_fallback_uri(size_t buffer, size_t bytes) { return fmt::format("{}{}-{}", kMarker, buffer, bytes); }

std::optional<size_t> meshopt_fallback_size(const std::string& lookup) {
    const size_t at = lookup.rfind(kMarker);
    if (at == std::string::npos) return std::nullopt;
    const std::string rest = lookup.substr(at + std::strlen(kMarker));
    const size_t dash = rest.find('-');
    if (dash == std::string::npos) return std::nullopt;
    try {
        return size_t(std::stoull(rest.substr(dash + 1)));
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

bool add_meshopt_fallback_uris(nlohmann::json& doc, bool binary) {
    if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return false;
    bool changed = false;
    nlohmann::json& buffers = doc["buffers"];
    for (size_t i = 0; i < buffers.size(); ++i) {
        nlohmann::json& b = buffers[i];
        if (!b.is_object() || b.contains("uri") || !b.contains("extensions") || !b["extensions"].is_object() ||
            !b["extensions"].contains(kExt))
            continue;
        if (binary && i == 0) continue;  // a GLB's first buffer without a uri is its BIN chunk
        const nlohmann::json& length = b.contains("byteLength") ? b["byteLength"] : nlohmann::json();
        if (!length.is_number_unsigned()) continue;  // tinygltf reports it
        b["uri"] = meshopt_fallback_uri(i, length.get<size_t>());
        changed = true;
    }
    return changed;
}

void decode_meshopt_views(tinygltf::Model& model, const std::string& path) {
    for (size_t i = 0; i < model.bufferViews.size(); ++i) {
        const tinygltf::BufferView& view = model.bufferViews[i];
        if (view.extensions.empty()) continue;
        const auto found = view.extensions.find(kExt);
        if (found == view.extensions.end()) continue;
        const tinygltf::Value& ext = found->second;
        const std::string ptr = fmt::format("/bufferViews/{}/extensions/{}", i, kExt);
        if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
            fail(path, fmt::format("/bufferViews/{}/buffer", i), "buffer out of range");
        tinygltf::Buffer& target = model.buffers[size_t(view.buffer)];
        if (target.uri.rfind(kMarker, 0) != 0) continue;  // the buffer has data of its own: use it
        const size_t source = gltf::extension_uint(ext, "buffer", size_t(-1), path, ptr);
        if (source >= model.buffers.size()) fail(path, ptr + "/buffer", "source buffer out of range");
        const std::vector<unsigned char>& src = model.buffers[source].data;
        const size_t offset = gltf::extension_uint(ext, "byteOffset", 0, path, ptr);
        const size_t length = gltf::extension_uint(ext, "byteLength", size_t(-1), path, ptr);
        const size_t stride = gltf::extension_uint(ext, "byteStride", 0, path, ptr);
        const size_t count = gltf::extension_uint(ext, "count", size_t(-1), path, ptr);
        const std::string mode = gltf::extension_text(ext, "mode", "");
        const std::string filter = gltf::extension_text(ext, "filter", "NONE");
        if (length == size_t(-1) || count == size_t(-1)) fail(path, ptr, "byteLength and count are required");
        if (offset > src.size() || length > src.size() - offset)
            fail(path, ptr, fmt::format("bytes {}..{} are outside source buffer {} ({} bytes)", offset, offset + length,
                                        source, src.size()));
        // The decoded bytes must fit the view and the view its buffer, before anything is written.
        if (stride == 0 || count > (size_t(1) << 32) / stride)
            fail(path, ptr, fmt::format("count {} x byteStride {} is not a valid size", count, stride));
        const size_t decoded = count * stride;
        if (decoded > view.byteLength)
            fail(path, ptr, fmt::format("count {} x byteStride {} = {} bytes exceeds the bufferView's byteLength {}",
                                        count, stride, decoded, view.byteLength));
        if (view.byteOffset > target.data.size() || view.byteLength > target.data.size() - view.byteOffset)
            fail(path, fmt::format("/bufferViews/{}", i), "the bufferView is outside its buffer");
        unsigned char* dest = target.data.data() + view.byteOffset;
        const unsigned char* in = src.data() + offset;
        int rc = 0;
        if (mode == "ATTRIBUTES") {
            if (stride % 4 != 0 || stride > 256)
                fail(path, ptr + "/byteStride", fmt::format("ATTRIBUTES byteStride {} is not a multiple of 4 up to 256", stride));
            rc = meshopt_decodeVertexBuffer(dest, count, stride, in, length);
        } else if (mode == "TRIANGLES" || mode == "INDICES") {
            if (stride != 2 && stride != 4)
                fail(path, ptr + "/byteStride", fmt::format("{} byteStride {} is not 2 or 4", mode, stride));
            if (mode == "TRIANGLES" && count % 3 != 0)
                fail(path, ptr + "/count", fmt::format("TRIANGLES count {} is not a multiple of 3", count));
            rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(dest, count, stride, in, length)
                                     : meshopt_decodeIndexSequence(dest, count, stride, in, length);
        } else {
            fail(path, ptr + "/mode", fmt::format("mode '{}' (expected ATTRIBUTES, TRIANGLES or INDICES)", mode));
        }
        if (rc != 0) fail(path, ptr, fmt::format("corrupt {} stream (meshopt error {})", mode, rc));
        if (filter == "NONE") continue;
        if (mode != "ATTRIBUTES") fail(path, ptr + "/filter", fmt::format("filter {} needs mode ATTRIBUTES", filter));
        if (filter == "OCTAHEDRAL" && (stride == 4 || stride == 8)) meshopt_decodeFilterOct(dest, count, stride);
        else if (filter == "QUATERNION" && stride == 8) meshopt_decodeFilterQuat(dest, count, stride);
        else if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(dest, count, stride);
        else fail(path, ptr + "/filter", fmt::format("filter '{}' with byteStride {} is not valid", filter, stride));
    }
}

}  // namespace whitted
