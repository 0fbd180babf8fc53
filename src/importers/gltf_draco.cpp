#include "importers/gltf_draco.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>

#include <draco/attributes/attribute_quantization_transform.h>
#include <draco/compression/decode.h>
#include <draco/core/quantization_utils.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "importers/gltf_json.h"
#include "importers/located_error.h"

namespace whitted {

namespace {

constexpr const char* kExt = "KHR_draco_mesh_compression";
constexpr const char* kIndices = "whitted_indices";  // where detach_draco_indices keeps `indices`

/// One primitive to decode: its stream and what the extension maps onto it.
struct Job {
    size_t mesh = 0, primitive = 0;
    size_t view = 0;
    size_t stream = 0;                       ///< index into the decoded streams (one per view)
    int indices = -1;                        ///< accessor, -1 without
    std::map<std::string, uint32_t> ids;     ///< attribute name -> Draco unique id
    std::string ptr;                         ///< JSON pointer of the extension object
};

/// A decoded stream, or why it did not decode.
struct Stream {
    std::unique_ptr<draco::Mesh> mesh;
    std::string error;
};

Stream decode_stream(const tinygltf::Model& model, size_t view_index) {
    Stream s;
    const tinygltf::BufferView& view = model.bufferViews[view_index];
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
        s.error = "its bufferView's buffer is out of range";
        return s;
    }
    const std::vector<unsigned char>& data = model.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
        s.error = fmt::format("bufferView {} is outside its buffer", view_index);
        return s;
    }
    try {
        draco::DecoderBuffer in;
        in.Init(reinterpret_cast<const char*>(data.data() + view.byteOffset), view.byteLength);
        draco::Decoder decoder;
        // Quantized attributes come as their integers and quantization (dequantized here, which
        // gives the step the declared bounds may be off by); normals keep their octahedral decoding.
        for (const auto type : {draco::GeometryAttribute::POSITION, draco::GeometryAttribute::TEX_COORD,
                                draco::GeometryAttribute::COLOR, draco::GeometryAttribute::GENERIC})
            decoder.SetSkipAttributeTransform(type);
        auto decoded = decoder.DecodeMeshFromBuffer(&in);
        if (!decoded.ok())
            s.error = fmt::format("corrupt Draco stream in bufferView {} ({})", view_index,
                                  decoded.status().error_msg_string());
        else
            s.mesh = std::move(decoded).value();
    } catch (const std::bad_alloc&) {
        s.error = fmt::format("out of memory decoding the Draco stream in bufferView {}", view_index);
    } catch (const std::exception& e) {
        s.error = fmt::format("corrupt Draco stream in bufferView {} ({})", view_index, e.what());
    }
    if (s.mesh && s.mesh->num_faces() == 0 && s.error.empty())
        s.error = fmt::format("the Draco stream in bufferView {} holds no triangles", view_index);
    return s;
}

template <typename T>
bool convert_points(const draco::Mesh& mesh, const draco::PointAttribute& att, int components, unsigned char* out) {
    T value[16] = {};
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p) {
        if (!att.ConvertValue<T>(att.mapped_index(p), int8_t(components), value)) return false;
        std::memcpy(out, value, sizeof(T) * size_t(components));
        out += sizeof(T) * size_t(components);
    }
    return true;
}

/// A quantized attribute's quantization, when it has one.
std::optional<draco::AttributeQuantizationTransform> quantization(const draco::PointAttribute& att) {
    const draco::AttributeTransformData* data = att.GetAttributeTransformData();
    if (data == nullptr || data->transform_type() != draco::ATTRIBUTE_QUANTIZATION_TRANSFORM) return std::nullopt;
    draco::AttributeQuantizationTransform q;
    if (!q.InitFromAttribute(att) || q.quantization_bits() < 1 || q.quantization_bits() > 30) return std::nullopt;
    return q;
}

/// The step between two quantized values (0 for an attribute that is not quantized).
float quantization_step(const draco::PointAttribute& att) {
    const auto q = quantization(att);
    return q ? q->range() / float((1u << q->quantization_bits()) - 1) : 0.f;
}

/// Quantized integers to floats, as Draco's own inverse transform does.
bool dequantize_points(const draco::Mesh& mesh, const draco::PointAttribute& att,
                       const draco::AttributeQuantizationTransform& q, int components, unsigned char* out) {
    draco::Dequantizer dq;
    if (!dq.Init(q.range(), int32_t((1u << q.quantization_bits()) - 1)) || size_t(components) > q.min_values().size())
        return false;
    uint32_t value[16] = {};
    float f[16];
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p) {
        if (!att.ConvertValue<uint32_t>(att.mapped_index(p), int8_t(components), value)) return false;
        for (int c = 0; c < components; ++c) f[c] = dq.DequantizeFloat(int32_t(value[c])) + q.min_value(c);
        std::memcpy(out, f, sizeof(float) * size_t(components));
        out += sizeof(float) * size_t(components);
    }
    return true;
}

bool convert_attribute(const draco::Mesh& mesh, const draco::PointAttribute& att, int component_type, int components,
                       unsigned char* out) {
    if (const auto q = quantization(att))
        return component_type == TINYGLTF_COMPONENT_TYPE_FLOAT && dequantize_points(mesh, att, *q, components, out);
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return convert_points<int8_t>(mesh, att, components, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return convert_points<uint8_t>(mesh, att, components, out);
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return convert_points<int16_t>(mesh, att, components, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return convert_points<uint16_t>(mesh, att, components, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return convert_points<uint32_t>(mesh, att, components, out);
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return convert_points<float>(mesh, att, components, out);
        default:
            return false;
    }
}

void write_indices(const draco::Mesh& mesh, int component_type, unsigned char* out) {
    const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(component_type)));
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.face(f)[k].value();
            std::memcpy(out, &v, size);  // little-endian: the low bytes (the count fits the type, checked)
            out += size;
        }
}

uint64_t accessor_bytes(const tinygltf::Accessor& a) {
    return uint64_t(a.count) * uint64_t(tinygltf::GetNumComponentsInType(uint32_t(a.type))) *
           uint64_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
}

/// The decoded data of one primitive: a new buffer, and the accessors that point into it.
struct Output {
    std::vector<unsigned char> bytes;
    std::vector<std::pair<int, size_t>> accessors;  ///< accessor, byte offset in `bytes`
    std::vector<size_t> sizes;                      ///< bytes of each accessor's data
    std::vector<float> steps;                       ///< each accessor's quantization step (0: exact)
    std::string error, error_ptr;
};

/// A float accessor's declared min/max against its decoded values. Quantization moves values by
/// up to one step (the writer may give the bounds of the data before quantization): within that,
/// the bounds are widened to the decoded data (so the importer's general check passes); beyond
/// it, a located error.
void check_declared_bounds(tinygltf::Accessor& a, int index, const unsigned char* data, float step,
                           const std::string& path) {
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || (a.minValues.empty() && a.maxValues.empty())) return;
    const size_t n = size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    if ((!a.minValues.empty() && a.minValues.size() != n) || (!a.maxValues.empty() && a.maxValues.size() != n))
        return;  // the general check reports the lengths
    std::vector<double> lo(n, INFINITY), hi(n, -INFINITY);
    for (size_t i = 0; i < a.count; ++i)
        for (size_t c = 0; c < n; ++c) {
            float v;
            std::memcpy(&v, data + 4 * (i * n + c), 4);
            if (std::isnan(v)) continue;  // reported where the attribute is read
            lo[c] = std::min(lo[c], double(v)), hi[c] = std::max(hi[c], double(v));
        }
    for (size_t c = 0; c < n; ++c) {
        auto widen = [&](std::vector<double>& bounds, double actual, bool is_min) {
            if (bounds.empty() || (is_min ? actual >= bounds[c] : actual <= bounds[c])) return;
            const double by = std::fabs(actual - bounds[c]);
            if (by > double(step) + 1e-4 * std::max(1.0, std::fabs(bounds[c])))
                throw Error(file_loc(path, fmt::format("/accessors/{}/{}/{}", index, is_min ? "min" : "max", c)),
                            fmt::format("the Draco stream decodes to {}, outside the declared {} {} by more than its "
                                        "quantization step {}",
                                        actual, is_min ? "minimum" : "maximum", bounds[c], step));
            bounds[c] = actual;
        };
        widen(a.minValues, lo[c], true);
        widen(a.maxValues, hi[c], false);
    }
}

}  // namespace

bool detach_draco_indices(nlohmann::json& doc) {
    if (!doc.is_object() || !doc.contains("meshes") || !doc["meshes"].is_array()) return false;
    bool changed = false;
    for (nlohmann::json& mesh : doc["meshes"]) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (nlohmann::json& p : mesh["primitives"]) {
            if (!p.is_object() || !p.contains("indices") || !p.contains("extensions") || !p["extensions"].is_object())
                continue;
            nlohmann::json& ext = p["extensions"];
            if (!ext.contains(kExt) || !ext[kExt].is_object()) continue;
            ext[kExt][kIndices] = p["indices"];
            p.erase("indices");
            changed = true;
        }
    }
    return changed;
}

std::vector<CompressedPrimitive> decode_draco_primitives(tinygltf::Model& model, const std::string& path,
                                                         size_t max_memory) {
    auto fail = [&](const std::string& ptr, const std::string& message) {
        throw Error(file_loc(path, ptr), message);
    };
    // Collect the primitives, restoring their indices, and check what the extension names.
    std::vector<Job> jobs;
    for (size_t m = 0; m < model.meshes.size(); ++m)
        for (size_t i = 0; i < model.meshes[m].primitives.size(); ++i) {
            tinygltf::Primitive& p = model.meshes[m].primitives[i];
            const tinygltf::Value* ext = gltf::find_extension(p.extensions, kExt);
            if (ext == nullptr) continue;
            Job job;
            job.mesh = m, job.primitive = i;
            job.ptr = fmt::format("/meshes/{}/primitives/{}/extensions/{}", m, i, kExt);
            if (!ext->IsObject()) fail(job.ptr, "the extension must be an object");
            if (const tinygltf::Value* idx = gltf::find_member(ext, kIndices)) {
                int a = -1;
                if (!gltf::as_int(idx, a) || a < 0 || size_t(a) >= model.accessors.size())
                    fail(fmt::format("/meshes/{}/primitives/{}/indices", m, i), "accessor out of range");
                p.indices = a;
            }
            job.indices = p.indices;
            job.view = gltf::extension_uint(*ext, "bufferView", size_t(-1), path, job.ptr);
            if (job.view >= model.bufferViews.size()) fail(job.ptr + "/bufferView", "bufferView out of range");
            const tinygltf::Value* attributes = gltf::find_member(ext, "attributes");
            if (attributes == nullptr || !attributes->IsObject())
                fail(job.ptr + "/attributes", "attributes must be an object of attribute ids");
            for (const std::string& name : attributes->Keys()) {
                const size_t id = gltf::extension_uint(*attributes, name.c_str(), 0, path, job.ptr + "/attributes");
                if (p.attributes.find(name) == p.attributes.end())
                    fail(job.ptr + "/attributes/" + name, fmt::format("the primitive has no {} attribute", name));
                // The primitive's accessor for it: checked here, before the decoders index with it.
                const int accessor = p.attributes.at(name);
                if (accessor < 0 || size_t(accessor) >= model.accessors.size())
                    fail(fmt::format("/meshes/{}/primitives/{}/attributes/{}", m, i, name), "accessor out of range");
                job.ids[name] = uint32_t(id);
            }
            const bool triangles = p.mode == TINYGLTF_MODE_TRIANGLES || p.mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
                                   p.mode == TINYGLTF_MODE_TRIANGLE_FAN;
            if (!triangles) continue;  // points and lines are not rendered (the importer notes them)
            p.mode = TINYGLTF_MODE_TRIANGLES;  // Draco decodes to a triangle list
            jobs.push_back(std::move(job));
        }
    if (jobs.empty()) return {};

    // Decode each stream once, in parallel.
    std::vector<size_t> views;
    std::map<size_t, size_t> stream_of_view;
    for (Job& j : jobs) {
        const auto [it, fresh] = stream_of_view.emplace(j.view, views.size());
        if (fresh) views.push_back(j.view);
        j.stream = it->second;
    }
    std::vector<Stream> streams(views.size());
    tbb::parallel_for(size_t(0), views.size(), [&](size_t k) { streams[k] = decode_stream(model, views[k]); });
    for (const Job& j : jobs)
        if (const Stream& s = streams[j.stream]; !s.error.empty()) fail(j.ptr, s.error);

    // Each accessor is filled once: by the first primitive that names it. One named by primitives
    // with different streams is ambiguous.
    std::map<int, size_t> owner_view;
    std::vector<std::vector<std::pair<int, uint32_t>>> fills(jobs.size());  // accessor, id (indices: ~0u)
    for (size_t k = 0; k < jobs.size(); ++k) {
        const Job& j = jobs[k];
        const tinygltf::Primitive& p = model.meshes[j.mesh].primitives[j.primitive];
        auto claim = [&](int accessor, uint32_t id) {
            auto [it, fresh] = owner_view.emplace(accessor, j.view);
            if (fresh) fills[k].emplace_back(accessor, id);
            else if (it->second != j.view)
                fail(fmt::format("/accessors/{}", accessor),
                     fmt::format("the accessor is decoded from two Draco streams (bufferViews {} and {})", it->second,
                                 j.view));
        };
        if (j.indices >= 0) claim(j.indices, ~0u);
        for (const auto& [name, id] : j.ids) claim(p.attributes.at(name), id);
    }

    // Convert into new buffers (in parallel), checking counts and component counts.
    std::vector<Output> outputs(jobs.size());
    tbb::parallel_for(size_t(0), jobs.size(), [&](size_t k) {
        const Job& j = jobs[k];
        const draco::Mesh& mesh = *streams[j.stream].mesh;
        Output& out = outputs[k];
        auto error = [&](int accessor, std::string message) {
            if (out.error.empty()) out.error = std::move(message), out.error_ptr = fmt::format("/accessors/{}", accessor);
        };
        size_t total = 0;
        for (const auto& [accessor, id] : fills[k]) {
            const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
            const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
            const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
            if (components <= 0 || components > 16 || csize <= 0) return error(accessor, "invalid type or componentType");
            const size_t count = id == ~0u ? size_t(mesh.num_faces()) * 3 : size_t(mesh.num_points());
            if (a.count != count)
                return error(accessor, fmt::format("count {} differs from the Draco stream's {} {} (bufferView {})",
                                                   a.count, count, id == ~0u ? "indices" : "points", j.view));
            if (id == ~0u) {
                const int t = a.componentType;
                const uint64_t limit = t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 0xFFu
                                       : t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 0xFFFFu
                                       : t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 0xFFFFFFFFu
                                                                                     : 0;
                if (limit == 0) return error(accessor, "indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
                if (mesh.num_points() > limit + 1)
                    return error(accessor, fmt::format("{} points do not fit indices of componentType {}",
                                                       mesh.num_points(), t));
            } else {
                const draco::PointAttribute* att = mesh.GetAttributeByUniqueId(id);
                if (att == nullptr)
                    return error(accessor, fmt::format("the Draco stream in bufferView {} has no attribute id {}",
                                                       j.view, id));
                if (att->num_components() != components)
                    return error(accessor, fmt::format("type has {} components, the Draco attribute id {} has {}",
                                                       components, id, int(att->num_components())));
            }
            const size_t bytes = count * size_t(components) * size_t(csize);
            if (bytes > max_memory || total > max_memory - bytes)
                return error(accessor, fmt::format("the decoded data exceeds the memory limit of {} bytes", max_memory));
            out.accessors.emplace_back(accessor, total);
            out.sizes.push_back(bytes);
            out.steps.push_back(id == ~0u ? 0.f : quantization_step(*mesh.GetAttributeByUniqueId(id)));
            total += (bytes + 3) & ~size_t(3);  // each accessor 4-byte aligned
        }
        try {
            out.bytes.assign(total, 0);
        } catch (const std::bad_alloc&) {
            return error(fills[k].empty() ? 0 : fills[k][0].first, "out of memory for the decoded data");
        }
        for (size_t n = 0; n < out.accessors.size(); ++n) {
            const auto [accessor, offset] = out.accessors[n];
            const uint32_t id = fills[k][n].second;
            const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
            unsigned char* dest = out.bytes.data() + offset;
            if (id == ~0u) {
                write_indices(mesh, a.componentType, dest);
            } else if (!convert_attribute(mesh, *mesh.GetAttributeByUniqueId(id), a.componentType,
                                          tinygltf::GetNumComponentsInType(uint32_t(a.type)), dest)) {
                return error(accessor, fmt::format("the Draco attribute id {} does not convert to componentType {}",
                                                   id, a.componentType));
            }
        }
    });

    // Attach, in primitive order (deterministic buffer and view numbers).
    std::vector<CompressedPrimitive> records;
    for (size_t k = 0; k < jobs.size(); ++k) {
        Output& out = outputs[k];
        if (!out.error.empty()) fail(out.error_ptr, out.error);
        const Job& j = jobs[k];
        const size_t buffer = model.buffers.size();
        for (size_t n = 0; n < out.accessors.size(); ++n) {
            const auto [accessor, offset] = out.accessors[n];
            tinygltf::BufferView view;
            view.buffer = int(buffer);
            view.byteOffset = offset;
            view.byteLength = out.sizes[n];
            model.bufferViews.push_back(view);
            tinygltf::Accessor& a = model.accessors[size_t(accessor)];
            a.bufferView = int(model.bufferViews.size() - 1);
            a.byteOffset = 0;
            check_declared_bounds(a, accessor, out.bytes.data() + offset, out.steps[n], path);
        }
        tinygltf::Buffer b;
        b.data = std::move(out.bytes);
        model.buffers.push_back(std::move(b));
        // Primitives sharing a stream each report it whole, with the accessors they name.
        const tinygltf::Primitive& p = model.meshes[j.mesh].primitives[j.primitive];
        uint64_t decoded = j.indices >= 0 ? accessor_bytes(model.accessors[size_t(j.indices)]) : 0;
        for (const auto& entry : j.ids) decoded += accessor_bytes(model.accessors[size_t(p.attributes.at(entry.first))]);
        records.push_back({fmt::format("/meshes/{}/primitives/{}", j.mesh, j.primitive), "draco",
                           model.bufferViews[j.view].byteLength, decoded});
    }
    return records;
}

}  // namespace whitted
