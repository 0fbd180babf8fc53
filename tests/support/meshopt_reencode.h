// A lossless EXT_meshopt_compression re-encoder for GLB files, written with libmeshoptimizer's
// encoders, for the test that a model and its meshopt variant render bit for bit alike. Unlike an
// optimiser it changes nothing but the bufferViews: the JSON's numbers, the accessors and the
// textures stay as they are. Every bufferView that only accessors read is encoded (ATTRIBUTES
// with the view's stride, the accessor's element size or 4 bytes; index views as TRIANGLES where
// that round-trips exactly, else INDICES) into the GLB's BIN chunk, and its uncompressed bytes
// move to a fallback buffer that carries no data, so an importer that ignored the extension
// could not render the file.
#pragma once

#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "tests/support/test_importer_util.h"

namespace whitted::test {

struct MeshoptReencoded {
    std::vector<uint8_t> glb;
    int attribute_views = 0, triangle_views = 0, index_views = 0;  ///< views encoded per mode
};

namespace detail {
inline uint32_t read_u32(const std::vector<uint8_t>& b, size_t at) {
    uint32_t v;
    std::memcpy(&v, b.data() + at, 4);
    return v;
}
inline size_t component_bytes(int type) { return type == 5120 || type == 5121 ? 1 : type == 5122 || type == 5123 ? 2 : 4; }
inline size_t component_count(const std::string& t) {
    return t == "SCALAR" ? 1 : t == "VEC2" ? 2 : t == "VEC3" ? 3 : t == "VEC4" || t == "MAT2" ? 4 : t == "MAT3" ? 9 : 16;
}
}  // namespace detail

/// `glb` (a GLB file with one BIN chunk holding buffer 0) re-encoded with EXT_meshopt_compression.
inline MeshoptReencoded meshopt_reencode(const std::vector<uint8_t>& glb) {
    using nlohmann::json;
    using detail::read_u32;
    if (glb.size() < 20 || read_u32(glb, 0) != 0x46546C67) throw std::runtime_error("not a GLB file");
    const uint32_t json_size = read_u32(glb, 12);
    json doc = json::parse(glb.begin() + 20, glb.begin() + 20 + json_size);
    const size_t bin_at = 20 + json_size;
    if (bin_at + 8 > glb.size() || doc["buffers"].size() != 1) throw std::runtime_error("expected one BIN buffer");
    const std::vector<uint8_t> bin(glb.begin() + long(bin_at + 8), glb.begin() + long(bin_at + 8 + read_u32(glb, bin_at)));

    // What reads each view: accessors (element size), primitive indices, anything else.
    json& views = doc["bufferViews"];
    std::map<size_t, std::set<size_t>> element_sizes;
    std::set<size_t> index_views, other_views;
    std::map<size_t, size_t> accessor_view;
    auto note_view = [&](const json& holder, size_t size) {
        if (holder.contains("bufferView")) element_sizes[holder["bufferView"].get<size_t>()].insert(size);
    };
    for (size_t a = 0; a < doc.value("accessors", json::array()).size(); ++a) {
        const json& acc = doc["accessors"][a];
        const size_t size = detail::component_bytes(acc["componentType"]) * detail::component_count(acc["type"]);
        note_view(acc, size);
        if (acc.contains("bufferView")) accessor_view[a] = acc["bufferView"];
        if (acc.contains("sparse")) {
            note_view(acc["sparse"]["indices"], detail::component_bytes(acc["sparse"]["indices"]["componentType"]));
            note_view(acc["sparse"]["values"], size);
        }
    }
    for (const json& mesh : doc.value("meshes", json::array()))
        for (const json& prim : mesh["primitives"])
            if (prim.contains("indices") && accessor_view.count(prim["indices"])) {
                const size_t v = accessor_view[prim["indices"]];
                (prim.value("mode", 4) == 4 ? index_views : other_views).insert(v);
            }
    for (const json& image : doc.value("images", json::array()))
        if (image.contains("bufferView")) other_views.insert(image["bufferView"].get<size_t>());

    MeshoptReencoded out;
    std::vector<uint8_t> new_bin;
    auto append = [&](const uint8_t* data, size_t size) {
        while (new_bin.size() % 4) new_bin.push_back(0);
        const size_t at = new_bin.size();
        new_bin.insert(new_bin.end(), data, data + size);
        return at;
    };
    for (size_t v = 0; v < views.size(); ++v) {
        json& view = views[v];
        const size_t offset = view.value("byteOffset", size_t(0)), length = view["byteLength"];
        const uint8_t* src = bin.data() + offset;
        json ext;
        std::vector<uint8_t> stream;
        const auto sizes = element_sizes.find(v);
        if (other_views.count(v) || sizes == element_sizes.end()) {
            // Images and views no accessor reads stay as they are, in the BIN chunk.
        } else if (index_views.count(v) && sizes->second.size() == 1 && *sizes->second.begin() != 1) {
            const size_t stride = *sizes->second.begin(), count = length / stride;
            std::vector<uint32_t> indices(count), decoded(count);
            for (size_t i = 0; i < count; ++i) {
                uint16_t s16;
                std::memcpy(stride == 2 ? static_cast<void*>(&s16) : static_cast<void*>(&indices[i]), src + i * stride, stride);
                if (stride == 2) indices[i] = s16;
            }
            stream.resize(meshopt_encodeIndexBufferBound(count, count));
            stream.resize(meshopt_encodeIndexBuffer(stream.data(), stream.size(), indices.data(), count));
            const bool exact = count % 3 == 0 &&
                               meshopt_decodeIndexBuffer(decoded.data(), count, 4, stream.data(), stream.size()) == 0 &&
                               decoded == indices;
            if (!exact) {
                stream.resize(meshopt_encodeIndexSequenceBound(count, count));
                stream.resize(meshopt_encodeIndexSequence(stream.data(), stream.size(), indices.data(), count));
            }
            ++(exact ? out.triangle_views : out.index_views);
            ext = {{"byteStride", stride}, {"count", count}, {"mode", exact ? "TRIANGLES" : "INDICES"}};
        } else {
            size_t stride = view.value("byteStride", size_t(0));
            if (stride == 0) stride = sizes->second.size() == 1 ? *sizes->second.begin() : 4;
            if (stride % 4 || length % 4) stride = 0;
            if (stride && length % stride) stride = 4;
            if (stride && stride <= 256) {
                stream.resize(meshopt_encodeVertexBufferBound(length / stride, stride));
                stream.resize(meshopt_encodeVertexBuffer(stream.data(), stream.size(), src, length / stride, stride));
                ++out.attribute_views;
                ext = {{"byteStride", stride}, {"count", length / stride}, {"mode", "ATTRIBUTES"}};
            }
        }
        if (ext.is_null()) {
            view["buffer"] = 0;
            view["byteOffset"] = append(src, length);
        } else {
            ext["buffer"] = 0;
            ext["byteOffset"] = append(stream.data(), stream.size());
            ext["byteLength"] = stream.size();
            view["buffer"] = 1;  // the fallback: same offsets as before, no data
            view["extensions"]["EXT_meshopt_compression"] = ext;
        }
    }
    doc["buffers"][0]["byteLength"] = new_bin.size();
    doc["buffers"].push_back({{"byteLength", bin.size()}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
        json& list = doc[key];
        if (!list.is_array()) list = json::array();
        list.push_back("EXT_meshopt_compression");
    }

    out.glb = make_glb(doc.dump(), std::move(new_bin));
    return out;
}

}  // namespace whitted::test
