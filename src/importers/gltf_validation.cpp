// Validation of a parsed glTF model: every reference, every byte range, every index value.
// The checks and their messages follow the Khronos glTF-Validator issue codes where one exists.

#include "importers/gltf_validation.h"

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "importers/gltf_accessor.h"
#include "importers/gltf_json.h"
#include "importers/warning_log.h"
#include "importers/located_error.h"
#include "core/error.h"

namespace whitted::gltf {

size_t triangle_count_for_mode(int mode, size_t n) {
    switch (mode) {
        case TINYGLTF_MODE_TRIANGLES:
            return n / 3;
        case TINYGLTF_MODE_TRIANGLE_STRIP:
        case TINYGLTF_MODE_TRIANGLE_FAN:
            return n >= 3 ? n - 2 : 0;
        default:
            return 0;
    }
}

int vertex_count_accessor(const tinygltf::Primitive& primitive) {
    auto it = primitive.attributes.find("POSITION");
    if (it != primitive.attributes.end()) return it->second;
    return primitive.attributes.empty() ? -1 : primitive.attributes.begin()->second;
}

namespace {

/// offset + stride * (count - 1) + elem <= length, without overflow.
bool range_fits(size_t offset, size_t count, size_t stride, size_t elem, size_t length) {
    if (count == 0) return offset <= length;
    const unsigned __int128 end =
        (unsigned __int128)offset + (unsigned __int128)stride * (count - 1) + (unsigned __int128)elem;
    return end <= (unsigned __int128)length;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

/// Parses the digits of "TEXCOORD_12" after the prefix; -1 when malformed.
int attribute_set(std::string_view name, std::string_view prefix) {
    if (!starts_with(name, prefix) || name.size() == prefix.size()) return -1;
    int v = 0;
    for (char c : name.substr(prefix.size())) {
        if (c < '0' || c > '9' || v > 100000) return -1;
        v = v * 10 + (c - '0');
    }
    return v;
}

/// A JSON pointer kept in pieces and joined only when an error or warning needs its text: the
/// checks run per accessor, bufferView, node and primitive, and formatting every pointer of a
/// 100,000-node file up front cost more than the checks. Appended pieces are views, so each
/// must outlive the Pointer (literals and strings of the model do).
class Pointer {
public:
    Pointer(const char* text) : m_head(text) {}
    Pointer(std::string text) : m_head(std::move(text)) {}

    Pointer operator+(std::string_view piece) const {
        Pointer p = *this;
        if (!piece.empty()) p.append({piece.data(), piece.size()});
        return p;
    }
    Pointer operator+(size_t index) const {
        Pointer p = *this;
        p.append({nullptr, index});
        return p;
    }

    std::string text() const {
        std::string out = m_head;
        for (size_t i = 0; i < m_count; ++i) {
            const Piece& piece = m_pieces[i];
            if (piece.text == nullptr)
                out += std::to_string(piece.value);
            else
                out.append(piece.text, piece.value);
        }
        return out;
    }

private:
    struct Piece {
        const char* text;  ///< nullptr: an index
        size_t value;      ///< the text's length, or the index
    };
    void append(const Piece& piece) {
        if (m_count == m_pieces.size()) {  // full: join what there is into the head
            m_head = text();
            m_count = 0;
        }
        m_pieces[m_count++] = piece;
    }

    std::string m_head;
    std::array<Piece, 8> m_pieces{};
    size_t m_count = 0;
};

class Validator {
public:
    Validator(const tinygltf::Model& model, const std::string& file, size_t max_memory, Scene& scene)
        : m_model(model), m_file(file), m_max_memory(max_memory), m_scene(scene) {}

    void run() {
        check_asset();
        check_buffer_views();
        for (size_t i = 0; i < m_model.accessors.size(); ++i) check_accessor(int(i));
        for (size_t i = 0; i < m_model.meshes.size(); ++i) check_mesh(int(i));
        for (size_t i = 0; i < m_model.samplers.size(); ++i) check_sampler(int(i));
        for (size_t i = 0; i < m_model.images.size(); ++i) check_image(int(i));
        for (size_t i = 0; i < m_model.textures.size(); ++i) check_texture(int(i));
        for (size_t i = 0; i < m_model.materials.size(); ++i) check_material(int(i));
        for (size_t i = 0; i < m_model.cameras.size(); ++i) check_camera(int(i));
        for (size_t i = 0; i < m_model.lights.size(); ++i) check_light(int(i));
        check_nodes();
        check_scenes();
        if (m_line_primitives > 0)
            m_warnings.add("lines", fmt::format("{} primitive(s) with mode POINTS, LINES, LINE_LOOP or LINE_STRIP "
                                                "skipped (whitted renders triangles only)",
                                                m_line_primitives));
        m_warnings.flush_to(m_scene);
    }

private:
    template <typename... Args>
    [[noreturn]] void fail(const Pointer& pointer, fmt::format_string<Args...> f, Args&&... args) const {
        throw Error(file_loc(m_file, pointer.text()), fmt::format(f, std::forward<Args>(args)...));
    }

    /// An index into an array of `size` objects named `what` ("mesh", "accessor").
    void check_ref(int index, size_t size, const Pointer& pointer, const char* what) const {
        if (index < 0 || size_t(index) >= size)
            fail(pointer, "unresolved reference: {} {} does not exist (the file has {})", what, index, size);
    }

    void check_finite(double v, const Pointer& pointer) const {
        if (!std::isfinite(v)) fail(pointer, "value {} is not a finite number", v);
    }

    // ---- asset ------------------------------------------------------------------------------
    void check_asset() const {
        // "2.0", "2.1": the major version must be 2 (glTF 1.0 is a different format).
        const std::string& v = m_model.asset.version;
        const size_t dot = v.find('.');
        const std::string major = v.substr(0, dot);
        if (major != "2") fail("/asset/version", "unsupported glTF version '{}' (whitted reads glTF 2.x)", v);
        const std::string& min = m_model.asset.minVersion;
        if (!min.empty() && min != "2.0")
            fail("/asset/minVersion", "glTF minVersion '{}' is newer than the 2.0 whitted implements", min);
    }

    // ---- buffer views ---------------------------------------------------------------------------
    void check_buffer_views() const {
        for (size_t i = 0; i < m_model.bufferViews.size(); ++i) {
            const tinygltf::BufferView& bv = m_model.bufferViews[i];
            const Pointer ptr = Pointer("/bufferViews/") + i;
            check_ref(bv.buffer, m_model.buffers.size(), ptr + "/buffer", "buffer");
            const size_t buffer_size = m_model.buffers[size_t(bv.buffer)].data.size();
            if (bv.byteLength < 1) fail(ptr + "/byteLength", "byteLength must be at least 1");
            if (!range_fits(bv.byteOffset, 1, 0, bv.byteLength, buffer_size))
                fail(ptr + "/byteLength",
                     "bufferView (byteOffset {} + byteLength {}) does not fit buffer {} ({} bytes)", bv.byteOffset,
                     bv.byteLength, bv.buffer, buffer_size);
            if (bv.byteStride != 0) {
                if (bv.byteStride < 4 || bv.byteStride > 252 || bv.byteStride % 4 != 0)
                    fail(ptr + "/byteStride", "byteStride {} is not a multiple of 4 in [4, 252]", bv.byteStride);
                if (bv.byteStride > bv.byteLength)
                    fail(ptr + "/byteStride", "byteStride ({}) is greater than byteLength ({})", bv.byteStride,
                         bv.byteLength);
            }
        }
    }

    // ---- accessors ------------------------------------------------------------------------------
    void check_accessor(int index) {
        const tinygltf::Accessor& a = m_model.accessors[size_t(index)];
        const Pointer ptr = Pointer("/accessors/") + size_t(index);
        const int csize = component_size(a.componentType);
        if (csize == 0) fail(ptr + "/componentType", "invalid componentType {}", a.componentType);
        const int ncomp = component_count(a.type);
        if (ncomp == 0) fail(ptr + "/type", "invalid accessor type");
        if (a.count < 1) fail(ptr + "/count", "count must be at least 1");
        if (a.normalized && (a.componentType == kFloat || a.componentType == kUnsignedInt))
            fail(ptr + "/normalized", "only BYTE and SHORT accessors may be normalized, not {}",
                 component_type_name(a.componentType));
        const size_t elem = element_size(a.componentType, a.type);

        if (a.bufferView >= 0) {
            check_ref(a.bufferView, m_model.bufferViews.size(), ptr + "/bufferView", "bufferView");
            const tinygltf::BufferView& bv = m_model.bufferViews[size_t(a.bufferView)];
            const size_t stride = bv.byteStride != 0 ? bv.byteStride : elem;
            if (bv.byteStride != 0 && bv.byteStride < elem)
                fail(ptr, "bufferView {} byteStride {} is less than the accessor element size {}", a.bufferView,
                     bv.byteStride, elem);
            if (a.byteOffset % size_t(csize) != 0)
                fail(ptr + "/byteOffset", "byteOffset {} is not a multiple of the component size {}", a.byteOffset,
                     csize);
            if (!range_fits(a.byteOffset, a.count, stride, elem, bv.byteLength))
                fail(ptr + "/count",
                     "{} elements of {} bytes (stride {}, byteOffset {}) do not fit bufferView {} ({} bytes)", a.count,
                     elem, stride, a.byteOffset, a.bufferView, bv.byteLength);
        } else if (a.count > m_max_memory / elem) {
            // Without a bufferView the elements are zeros: nothing bounds them but the memory budget.
            fail(ptr + "/count", "{} implicit (zero) elements of {} bytes exceed the memory limit of {} bytes", a.count,
                 elem, m_max_memory);
        }
        if (a.sparse.isSparse) check_sparse(index, a, elem);

        // Declared bounds: lengths, then the data against them (SCALAR..VEC4; matrices are not read).
        if (!a.minValues.empty() && a.minValues.size() != size_t(ncomp))
            fail(ptr + "/min", "min has {} values, the type needs {}", a.minValues.size(), ncomp);
        if (!a.maxValues.empty() && a.maxValues.size() != size_t(ncomp))
            fail(ptr + "/max", "max has {} values, the type needs {}", a.maxValues.size(), ncomp);
        if (ncomp <= 4 && (!a.minValues.empty() || !a.maxValues.empty())) check_bounds(index, a);
    }

    void check_sparse(int index, const tinygltf::Accessor& a, size_t elem) {
        const std::string ptr = fmt::format("/accessors/{}/sparse", index);
        const auto& s = a.sparse;
        if (s.count < 1) fail(ptr + "/count", "sparse count must be at least 1");
        if (size_t(s.count) > a.count)
            fail(ptr + "/count", "sparse accessor overrides more elements ({}) than the accessor contains ({})",
                 s.count, a.count);
        const int itype = s.indices.componentType;
        if (itype != kUnsignedByte && itype != kUnsignedShort && itype != kUnsignedInt)
            fail(ptr + "/indices/componentType",
                 "sparse indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or "
                 "UNSIGNED_INT, not {}",
                 itype);
        auto check_block = [&](const std::string& p, int bv_index, int offset, size_t bytes_each) {
            check_ref(bv_index, m_model.bufferViews.size(), p + "/bufferView", "bufferView");
            const tinygltf::BufferView& bv = m_model.bufferViews[size_t(bv_index)];
            if (bv.byteStride != 0)
                fail(p + "/bufferView", "only buffer views with vertex data may have byteStride (bufferView {})",
                     bv_index);
            if (offset < 0) fail(p + "/byteOffset", "negative byteOffset");
            if (!range_fits(size_t(offset), size_t(s.count), bytes_each, bytes_each, bv.byteLength))
                fail(p, "{} sparse entries of {} bytes from byteOffset {} do not fit bufferView {} ({} bytes)", s.count,
                     bytes_each, offset, bv_index, bv.byteLength);
        };
        check_block(ptr + "/indices", s.indices.bufferView, s.indices.byteOffset, size_t(component_size(itype)));
        check_block(ptr + "/values", s.values.bufferView, s.values.byteOffset, elem);
        // Indices strictly increasing and inside the accessor.
        const AccessorData d = accessor_data(m_model, index);
        const size_t isize = size_t(component_size(itype));
        int64_t previous = -1;
        for (size_t j = 0; j < d.sparse_count; ++j) {
            const uint32_t i = detail::load_index(d.sparse_indices + j * isize, itype);
            if (i >= a.count)
                fail(ptr + "/indices", "sparse index {} (entry {}) is not less than the accessor count {}", i, j,
                     a.count);
            if (int64_t(i) <= previous)
                fail(ptr + "/indices", "sparse indices are not strictly increasing (entry {}: {} after {})", j, i,
                     previous);
            previous = i;
        }
    }

    void check_bounds(int index, const tinygltf::Accessor& a) {
        // Elements outside the declared min/max (glTF-Validator ACCESSOR_ELEMENT_OUT_OF_*_BOUND).
        // Floats get a small tolerance for writers that print rounded bounds.
        AccessorData d = accessor_data(m_model, index);
        if (d.base == nullptr) d.count = std::min<size_t>(d.count, 1);  // implicit zeros: one is enough
        const bool is_float = a.componentType == kFloat;
        const int n = d.components;
        auto tolerance = [&](double bound) { return is_float ? 1e-4 * std::max(1.0, std::fabs(bound)) : 0.0; };
        bool bad = false;
        size_t bad_element = 0;
        int bad_component = 0;
        bool bad_is_min = false;
        double bad_value = 0;
        for_each_raw_element(d, [&](size_t i, const double* v) {
            if (bad) return;
            for (int c = 0; c < n; ++c) {
                if (std::isnan(v[c])) continue;  // NaN is handled where the attribute is read
                if (!a.minValues.empty() && v[c] < a.minValues[size_t(c)] - tolerance(a.minValues[size_t(c)])) {
                    bad = true, bad_is_min = true;
                } else if (!a.maxValues.empty() && v[c] > a.maxValues[size_t(c)] + tolerance(a.maxValues[size_t(c)])) {
                    bad = true, bad_is_min = false;
                }
                if (bad) {
                    bad_element = i, bad_component = c, bad_value = v[c];
                    return;
                }
            }
        });
        if (bad) {
            const double bound = bad_is_min ? a.minValues[size_t(bad_component)] : a.maxValues[size_t(bad_component)];
            fail(fmt::format("/accessors/{}/{}/{}", index, bad_is_min ? "min" : "max", bad_component),
                 "element {} component {} is {}, outside the declared {} {}", bad_element, bad_component, bad_value,
                 bad_is_min ? "minimum" : "maximum", bound);
        }
    }

    /// Largest value of an index accessor (cached: many primitives share one).
    uint32_t max_index(int accessor) {
        auto it = m_max_index.find(accessor);
        if (it != m_max_index.end()) return it->second;
        uint32_t m = 0;
        for_each_index(accessor_data(m_model, accessor), [&](size_t, uint32_t v) { m = std::max(m, v); });
        m_max_index.emplace(accessor, m);
        return m;
    }

    // ---- meshes ---------------------------------------------------------------------------------
    /// Checks an attribute's accessor type against what glTF (with KHR_mesh_quantization) allows.
    void check_attribute_format(const std::string& name, const tinygltf::Accessor& a, const Pointer& ptr) const {
        const int ct = a.componentType;
        const bool fl = ct == kFloat;
        const bool int8_16 = ct == kByte || ct == kUnsignedByte || ct == kShort || ct == kUnsignedShort;
        const bool unorm8_16 = (ct == kUnsignedByte || ct == kUnsignedShort) && a.normalized;
        const bool snorm8_16 = (ct == kByte || ct == kShort) && a.normalized;
        auto require = [&](int type, bool ok, const char* allowed) {
            if (a.type != type) fail(ptr, "attribute {} must be {}, not {}", name, type_name(type), type_name(a.type));
            if (!ok)
                fail(ptr, "attribute {} cannot use {}{} components (allowed: {})", name,
                     a.normalized ? "normalized " : "", component_type_name(ct), allowed);
        };
        if (name == "POSITION") {
            require(TINYGLTF_TYPE_VEC3, fl || int8_16, "FLOAT, or (KHR_mesh_quantization) BYTE/SHORT");
        } else if (name == "NORMAL") {
            require(TINYGLTF_TYPE_VEC3, fl || snorm8_16, "FLOAT, normalized BYTE/SHORT");
        } else if (name == "TANGENT") {
            require(TINYGLTF_TYPE_VEC4, fl || snorm8_16, "FLOAT, normalized BYTE/SHORT");
        } else if (attribute_set(name, "TEXCOORD_") >= 0) {
            require(TINYGLTF_TYPE_VEC2, fl || int8_16, "FLOAT, (normalized) BYTE/SHORT");
        } else if (attribute_set(name, "COLOR_") >= 0) {
            if (a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4)
                fail(ptr, "attribute {} must be VEC3 or VEC4, not {}", name, type_name(a.type));
            if (!(fl || unorm8_16))
                fail(ptr, "attribute {} cannot use {}{} components (allowed: FLOAT, normalized UNSIGNED_BYTE/SHORT)",
                     name, a.normalized ? "normalized " : "", component_type_name(ct));
        }
    }

    void check_mesh(int m) {
        const tinygltf::Mesh& mesh = m_model.meshes[size_t(m)];
        if (mesh.primitives.empty())
            m_warnings.add("no-primitives", fmt::format("/meshes/{}: mesh has no primitives", m));
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const Pointer ptr = Pointer("/meshes/") + size_t(m) + "/primitives/" + p;
            // References and formats of every attribute; equal counts (MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT).
            const int count_accessor = vertex_count_accessor(prim);
            size_t vertex_count = 0;
            if (count_accessor >= 0 && size_t(count_accessor) < m_model.accessors.size())
                vertex_count = m_model.accessors[size_t(count_accessor)].count;
            for (const auto& [name, acc] : prim.attributes) {
                const Pointer aptr = ptr + "/attributes/" + name;
                check_ref(acc, m_model.accessors.size(), aptr, "accessor");
                const tinygltf::Accessor& a = m_model.accessors[size_t(acc)];
                check_attribute_format(name, a, aptr);
                if (a.count != vertex_count)
                    fail(aptr, "all accessors of the same primitive must have the same count ({} has {}, expected {})",
                         name, a.count, vertex_count);
                if (a.componentType == kFloat &&
                    (name == "POSITION" || starts_with(name, "TEXCOORD_") || starts_with(name, "COLOR_")))
                    check_finite_data(acc, aptr);
            }
            if (prim.mode < 0 || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN)
                fail(ptr + "/mode", "invalid primitive mode {}", prim.mode);
            if (prim.material >= 0 || prim.material < -1)
                check_ref(prim.material, m_model.materials.size(), ptr + "/material", "material");
            size_t element_count = vertex_count;
            if (prim.indices != -1) {
                check_ref(prim.indices, m_model.accessors.size(), ptr + "/indices", "accessor");
                const tinygltf::Accessor& ia = m_model.accessors[size_t(prim.indices)];
                if (ia.type != TINYGLTF_TYPE_SCALAR ||
                    (ia.componentType != kUnsignedByte && ia.componentType != kUnsignedShort &&
                     ia.componentType != kUnsignedInt) ||
                    ia.normalized)
                    fail(ptr + "/indices", "indices must be a SCALAR UNSIGNED_BYTE/SHORT/INT accessor (accessor {})",
                         prim.indices);
                if (count_accessor >= 0) {
                    const uint32_t mi = max_index(prim.indices);
                    if (size_t(mi) >= vertex_count)
                        fail(ptr + "/indices", "index value {} is not less than the vertex count {} (accessor {})", mi,
                             vertex_count, prim.indices);
                }
                element_count = ia.count;
            }
            for (size_t t = 0; t < prim.targets.size(); ++t)
                for (const auto& [name, acc] : prim.targets[t]) {
                    const Pointer tptr = ptr + "/targets/" + t + "/" + name;
                    check_ref(acc, m_model.accessors.size(), tptr, "accessor");
                    if (m_model.accessors[size_t(acc)].count != vertex_count)
                        fail(tptr, "morph target accessor count {} differs from the vertex count {}",
                             m_model.accessors[size_t(acc)].count, vertex_count);
                }

            // Non-fatal findings, as glTF-Validator reports them (warnings).
            const bool triangles = prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
                                   prim.mode == TINYGLTF_MODE_TRIANGLE_FAN;
            if (!triangles) {
                ++m_line_primitives;
                continue;
            }
            if (prim.attributes.find("POSITION") == prim.attributes.end()) {
                m_warnings.add("no-position", fmt::format("{}: primitive has no POSITION attribute: skipped", ptr.text()));
                continue;
            }
            if (prim.mode == TINYGLTF_MODE_TRIANGLES && element_count % 3 != 0)
                m_warnings.add("incompatible-count",
                               fmt::format("{}: TRIANGLES primitive with {} vertices/indices (not a multiple of 3): "
                                           "the last {} dropped",
                                           ptr.text(), element_count, element_count % 3));
            if (triangle_count_for_mode(prim.mode, element_count) == 0)
                m_warnings.add("too-few",
                               fmt::format("{}: primitive has fewer than 3 vertices/indices: no triangles", ptr.text()));
        }
    }

    void check_finite_data(int accessor, const Pointer& ptr) {
        if (!m_finite_checked.emplace(accessor, true).second) return;
        AccessorData d = accessor_data(m_model, accessor);
        if (d.base == nullptr) d.count = 0;  // implicit zeros are finite: only sparse values to check
        bool bad = false;
        size_t bad_element = 0;
        for_each_element(d, [&](size_t i, const float* v) {
            for (int c = 0; c < d.components; ++c)
                if (!std::isfinite(v[c]) && !bad) bad = true, bad_element = i;
        });
        if (bad) fail(ptr, "accessor {} element {} holds a NaN or infinite value", accessor, bad_element);
    }

    // ---- textures, images, samplers, materials --------------------------------------------------
    void check_sampler(int i) const {
        const tinygltf::Sampler& s = m_model.samplers[size_t(i)];
        const std::string ptr = fmt::format("/samplers/{}", i);
        auto wrap_ok = [](int w) { return w == 33071 || w == 33648 || w == 10497; };
        if (s.magFilter != -1 && s.magFilter != 9728 && s.magFilter != 9729)
            fail(ptr + "/magFilter", "invalid magFilter {}", s.magFilter);
        if (s.minFilter != -1 && (s.minFilter < 9728 || s.minFilter > 9729) &&
            (s.minFilter < 9984 || s.minFilter > 9987))
            fail(ptr + "/minFilter", "invalid minFilter {}", s.minFilter);
        if (!wrap_ok(s.wrapS)) fail(ptr + "/wrapS", "invalid wrapS {}", s.wrapS);
        if (!wrap_ok(s.wrapT)) fail(ptr + "/wrapT", "invalid wrapT {}", s.wrapT);
    }

    void check_image(int i) const {
        const tinygltf::Image& img = m_model.images[size_t(i)];
        if (img.bufferView >= 0)
            check_ref(img.bufferView, m_model.bufferViews.size(), fmt::format("/images/{}/bufferView", i),
                      "bufferView");
    }

    void check_texture(int i) const {
        const tinygltf::Texture& t = m_model.textures[size_t(i)];
        const std::string ptr = fmt::format("/textures/{}", i);
        if (t.source != -1) check_ref(t.source, m_model.images.size(), ptr + "/source", "image");
        if (t.sampler != -1) check_ref(t.sampler, m_model.samplers.size(), ptr + "/sampler", "sampler");
        // Image sources given by texture-format extensions (KHR_texture_basisu, EXT_texture_webp, ...).
        for (const auto& [name, ext] : t.extensions) {
            int source = -1;
            const tinygltf::Value* v = find_member(&ext, "source");
            if (v == nullptr) continue;
            if (!as_int(v, source)) fail(ptr + "/extensions/" + name + "/source", "source is not an integer");
            check_ref(source, m_model.images.size(), ptr + "/extensions/" + name + "/source", "image");
        }
    }

    void check_texture_info(int index, int tex_coord, const tinygltf::ExtensionMap& extensions,
                            const std::string& ptr) const {
        if (index == -1) return;  // absent
        check_ref(index, m_model.textures.size(), ptr + "/index", "texture");
        if (tex_coord < 0) fail(ptr + "/texCoord", "texCoord {} is negative", tex_coord);
        check_texture_transform(find_extension(extensions, "KHR_texture_transform"),
                                ptr + "/extensions/KHR_texture_transform");
    }

    void check_texture_transform(const tinygltf::Value* xf, const std::string& ptr) const {
        if (xf == nullptr) return;
        auto check_numbers = [&](const char* key, size_t n) {
            const tinygltf::Value* v = find_member(xf, key);
            if (v == nullptr) return;
            if (n == 1) {
                if (!v->IsNumber()) fail(ptr + "/" + key, "{} is not a number", key);
                check_finite(v->GetNumberAsDouble(), ptr + "/" + key);
                return;
            }
            if (!v->IsArray() || v->ArrayLen() != n) fail(ptr + "/" + key, "{} must be an array of {} numbers", key, n);
            for (size_t k = 0; k < n; ++k) {
                const tinygltf::Value* e = find_element(v, k);
                if (!e->IsNumber()) fail(fmt::format("{}/{}/{}", ptr, key, k), "not a number");
                check_finite(e->GetNumberAsDouble(), fmt::format("{}/{}/{}", ptr, key, k));
            }
        };
        check_numbers("offset", 2);
        check_numbers("scale", 2);
        check_numbers("rotation", 1);
        const tinygltf::Value* tc = find_member(xf, "texCoord");
        int t = 0;
        if (tc != nullptr && (!as_int(tc, t) || t < 0))
            fail(ptr + "/texCoord", "texCoord must be a non-negative integer");
    }

    /// A textureInfo stored as raw JSON inside a material extension.
    void check_texture_info_value(const tinygltf::Value* info, const std::string& ptr) const {
        if (info == nullptr) return;
        if (!info->IsObject()) fail(ptr, "textureInfo is not an object");
        int index = -1, tex_coord = 0;
        if (!as_int(find_member(info, "index"), index)) fail(ptr + "/index", "textureInfo has no integer index");
        const tinygltf::Value* tc = find_member(info, "texCoord");
        if (tc != nullptr && !as_int(tc, tex_coord)) fail(ptr + "/texCoord", "texCoord is not an integer");
        check_ref(index, m_model.textures.size(), ptr + "/index", "texture");
        if (tex_coord < 0) fail(ptr + "/texCoord", "texCoord {} is negative", tex_coord);
        const tinygltf::Value* exts = find_member(info, "extensions");
        check_texture_transform(find_member(exts, "KHR_texture_transform"), ptr + "/extensions/KHR_texture_transform");
    }

    void check_material(int i) const {
        const tinygltf::Material& mat = m_model.materials[size_t(i)];
        const std::string ptr = fmt::format("/materials/{}", i);
        const auto& pbr = mat.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4)
            fail(ptr + "/pbrMetallicRoughness/baseColorFactor", "baseColorFactor needs 4 numbers, has {}",
                 pbr.baseColorFactor.size());
        for (size_t k = 0; k < 4; ++k)
            check_finite(pbr.baseColorFactor[k], fmt::format("{}/pbrMetallicRoughness/baseColorFactor/{}", ptr, k));
        check_finite(pbr.metallicFactor, ptr + "/pbrMetallicRoughness/metallicFactor");
        check_finite(pbr.roughnessFactor, ptr + "/pbrMetallicRoughness/roughnessFactor");
        if (mat.emissiveFactor.size() != 3)
            fail(ptr + "/emissiveFactor", "emissiveFactor needs 3 numbers, has {}", mat.emissiveFactor.size());
        for (size_t k = 0; k < 3; ++k) check_finite(mat.emissiveFactor[k], fmt::format("{}/emissiveFactor/{}", ptr, k));
        check_finite(mat.alphaCutoff, ptr + "/alphaCutoff");
        if (mat.alphaCutoff < 0) fail(ptr + "/alphaCutoff", "alphaCutoff {} is negative", mat.alphaCutoff);
        if (mat.alphaMode != "OPAQUE" && mat.alphaMode != "MASK" && mat.alphaMode != "BLEND")
            fail(ptr + "/alphaMode", "invalid alphaMode '{}'", mat.alphaMode);
        check_finite(mat.normalTexture.scale, ptr + "/normalTexture/scale");
        check_finite(mat.occlusionTexture.strength, ptr + "/occlusionTexture/strength");

        check_texture_info(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                           ptr + "/pbrMetallicRoughness/baseColorTexture");
        check_texture_info(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                           pbr.metallicRoughnessTexture.extensions,
                           ptr + "/pbrMetallicRoughness/metallicRoughnessTexture");
        check_texture_info(mat.normalTexture.index, mat.normalTexture.texCoord, mat.normalTexture.extensions,
                           ptr + "/normalTexture");
        check_texture_info(mat.occlusionTexture.index, mat.occlusionTexture.texCoord, mat.occlusionTexture.extensions,
                           ptr + "/occlusionTexture");
        check_texture_info(mat.emissiveTexture.index, mat.emissiveTexture.texCoord, mat.emissiveTexture.extensions,
                           ptr + "/emissiveTexture");

        // Khronos material extensions: numbers finite, every "...Texture" textureInfo resolved
        // (vendor extensions do not promise that naming convention, so they are left alone).
        for (const auto& [name, ext] : mat.extensions) {
            const std::string eptr = ptr + "/extensions/" + name;
            if (!ext.IsObject() || !starts_with(name, "KHR_")) continue;
            for (const std::string& key : ext.Keys()) {
                const tinygltf::Value& v = ext.Get(key);
                if (v.IsNumber()) check_finite(v.GetNumberAsDouble(), eptr + "/" + key);
                if (v.IsArray())
                    for (size_t k = 0; k < v.ArrayLen(); ++k) {
                        const tinygltf::Value* e = find_element(&v, k);
                        if (e->IsNumber()) check_finite(e->GetNumberAsDouble(), fmt::format("{}/{}/{}", eptr, key, k));
                    }
                if (key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0)
                    check_texture_info_value(&v, eptr + "/" + key);
            }
        }
    }

    // ---- cameras and lights ---------------------------------------------------------------------
    void check_camera(int i) const {
        const tinygltf::Camera& c = m_model.cameras[size_t(i)];
        const std::string ptr = fmt::format("/cameras/{}", i);
        if (c.type == "perspective") {
            const auto& p = c.perspective;
            const std::string pp = ptr + "/perspective";
            if (!std::isfinite(p.yfov) || p.yfov <= 0 || p.yfov >= std::numbers::pi)
                fail(pp + "/yfov", "yfov {} is not in (0, pi)", p.yfov);
            if (!std::isfinite(p.znear) || p.znear <= 0)
                fail(pp + "/znear", "znear {} is not a positive finite number", p.znear);
            if (!std::isfinite(p.zfar) || p.zfar < 0 || (p.zfar > 0 && p.zfar <= p.znear))
                fail(pp + "/zfar", "zfar {} must be greater than znear {}", p.zfar, p.znear);
            if (!std::isfinite(p.aspectRatio) || p.aspectRatio < 0)
                fail(pp + "/aspectRatio", "aspectRatio {} is not a positive finite number", p.aspectRatio);
        } else if (c.type == "orthographic") {
            const auto& o = c.orthographic;
            const std::string op = ptr + "/orthographic";
            if (!std::isfinite(o.xmag) || o.xmag == 0)
                fail(op + "/xmag", "xmag {} must be finite and non-zero", o.xmag);
            if (!std::isfinite(o.ymag) || o.ymag == 0)
                fail(op + "/ymag", "ymag {} must be finite and non-zero", o.ymag);
            if (!std::isfinite(o.znear) || o.znear < 0)
                fail(op + "/znear", "znear {} is not a finite number >= 0", o.znear);
            if (!std::isfinite(o.zfar) || o.zfar <= o.znear)
                fail(op + "/zfar", "zfar {} must be finite and greater than znear {}", o.zfar, o.znear);
        } else {
            fail(ptr + "/type", "invalid camera type '{}'", c.type);
        }
    }

    void check_light(int i) const {
        const tinygltf::Light& l = m_model.lights[size_t(i)];
        const std::string ptr = fmt::format("/extensions/KHR_lights_punctual/lights/{}", i);
        if (l.type != "point" && l.type != "spot" && l.type != "directional")
            fail(ptr + "/type", "invalid light type '{}'", l.type);
        if (!l.color.empty() && l.color.size() != 3)
            fail(ptr + "/color", "color needs 3 numbers, has {}", l.color.size());
        for (size_t k = 0; k < l.color.size(); ++k) {
            check_finite(l.color[k], fmt::format("{}/color/{}", ptr, k));
            if (l.color[k] < 0) fail(fmt::format("{}/color/{}", ptr, k), "negative color {}", l.color[k]);
        }
        if (!std::isfinite(l.intensity) || l.intensity < 0)
            fail(ptr + "/intensity", "intensity {} is not a finite number >= 0", l.intensity);
        if (!std::isfinite(l.range) || l.range < 0)
            fail(ptr + "/range", "range {} is not a positive finite number", l.range);
        if (l.type == "spot") {
            const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
            if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0 || outer <= inner ||
                outer > std::numbers::pi / 2 + 1e-6)
                fail(ptr + "/spot", "cone angles need 0 <= innerConeAngle ({}) < outerConeAngle ({}) <= pi/2", inner,
                     outer);
        }
    }

    // ---- nodes and scenes -----------------------------------------------------------------------
    void check_nodes() {
        const size_t n = m_model.nodes.size();
        std::vector<int> parent(n, -1);
        for (size_t i = 0; i < n; ++i) {
            const tinygltf::Node& node = m_model.nodes[i];
            const Pointer ptr = Pointer("/nodes/") + i;
            if (node.mesh != -1) check_ref(node.mesh, m_model.meshes.size(), ptr + "/mesh", "mesh");
            if (node.camera != -1) check_ref(node.camera, m_model.cameras.size(), ptr + "/camera", "camera");
            if (node.skin != -1) check_ref(node.skin, m_model.skins.size(), ptr + "/skin", "skin");
            check_transform(node, ptr);
            if (const tinygltf::Value* lp = find_extension(node.extensions, "KHR_lights_punctual")) {
                int light = -1;
                if (!as_int(find_member(lp, "light"), light))
                    fail(ptr + "/extensions/KHR_lights_punctual/light", "light is not an integer");
                check_ref(light, m_model.lights.size(), ptr + "/extensions/KHR_lights_punctual/light", "light");
            }
            if (const tinygltf::Value* gi = find_extension(node.extensions, "EXT_mesh_gpu_instancing"))
                check_gpu_instancing(gi, ptr + "/extensions/EXT_mesh_gpu_instancing");
            for (size_t c = 0; c < node.children.size(); ++c) {
                const int child = node.children[c];
                const Pointer cptr = ptr + "/children/" + c;
                check_ref(child, n, cptr, "node");
                if (size_t(child) == i) fail(cptr, "node {} is its own child", i);
                if (parent[size_t(child)] != -1)
                    fail(fmt::format("/nodes/{}", child),
                         "node {} has two parents (nodes {} and {}): the node "
                         "hierarchy must be a forest",
                         child, parent[size_t(child)], i);
                parent[size_t(child)] = int(i);
            }
        }
        // With one parent each, a node not reachable from a root lies on a cycle (NODE_LOOP).
        std::vector<char> reached(n, 0);
        std::vector<int> stack;
        for (size_t i = 0; i < n; ++i)
            if (parent[i] == -1) stack.push_back(int(i));
        while (!stack.empty()) {
            const int k = stack.back();
            stack.pop_back();
            reached[size_t(k)] = 1;
            for (int c : m_model.nodes[size_t(k)].children) stack.push_back(c);
        }
        for (size_t i = 0; i < n; ++i)
            if (!reached[i]) fail(fmt::format("/nodes/{}", i), "node {} is part of a node loop (cycle in children)", i);
        m_parent = std::move(parent);
    }

    void check_transform(const tinygltf::Node& node, const Pointer& ptr) const {
        auto check_array = [&](const std::vector<double>& v, size_t want, const char* key) {
            if (v.empty()) return;
            if (v.size() != want) fail(ptr + "/" + key, "{} needs {} numbers, has {}", key, want, v.size());
            for (size_t k = 0; k < v.size(); ++k)
                if (!std::isfinite(v[k])) check_finite(v[k], ptr + "/" + key + "/" + k);
        };
        check_array(node.matrix, 16, "matrix");
        check_array(node.translation, 3, "translation");
        check_array(node.rotation, 4, "rotation");
        check_array(node.scale, 3, "scale");
        if (node.rotation.size() == 4) {
            const double n2 = node.rotation[0] * node.rotation[0] + node.rotation[1] * node.rotation[1] +
                              node.rotation[2] * node.rotation[2] + node.rotation[3] * node.rotation[3];
            if (!(n2 > 1e-12)) fail(ptr + "/rotation", "rotation quaternion has zero length");
        }
    }

    void check_gpu_instancing(const tinygltf::Value* ext, const Pointer& ptr) {
        const tinygltf::Value* attrs = find_member(ext, "attributes");
        if (attrs == nullptr || !attrs->IsObject()) fail(ptr + "/attributes", "attributes object missing");
        size_t count = 0;
        bool first = true;
        for (const std::string& name : attrs->Keys()) {
            const Pointer aptr = ptr + "/attributes/" + name;
            int acc = -1;
            if (!as_int(&attrs->Get(name), acc)) fail(aptr, "attribute is not an accessor index");
            check_ref(acc, m_model.accessors.size(), aptr, "accessor");
            const tinygltf::Accessor& a = m_model.accessors[size_t(acc)];
            const bool ok_float = a.componentType == kFloat;
            const bool ok_snorm = (a.componentType == kByte || a.componentType == kShort) && a.normalized;
            if (name == "TRANSLATION" || name == "SCALE") {
                if (a.type != TINYGLTF_TYPE_VEC3 ||
                    !(ok_float || ok_snorm || a.componentType == kByte || a.componentType == kShort))
                    fail(aptr, "{} must be a VEC3 FLOAT (or BYTE/SHORT) accessor", name);
            } else if (name == "ROTATION") {
                if (a.type != TINYGLTF_TYPE_VEC4 || !(ok_float || ok_snorm))
                    fail(aptr, "ROTATION must be a VEC4 FLOAT or normalized BYTE/SHORT accessor");
            } else {
                continue;  // custom per-instance attributes (_ID, ...) are not read
            }
            if (!first && a.count != count)
                fail(aptr, "all instancing attributes must have the same count ({} vs {})", a.count, count);
            count = a.count, first = false;
            if (a.componentType == kFloat) check_finite_data(acc, aptr);
        }
    }

    void check_scenes() const {
        std::vector<int> listed_in(m_model.nodes.size(), -1);  // scene that last listed the node
        for (size_t s = 0; s < m_model.scenes.size(); ++s) {
            const auto& roots = m_model.scenes[s].nodes;
            for (size_t k = 0; k < roots.size(); ++k) {
                const Pointer ptr = Pointer("/scenes/") + s + "/nodes/" + k;
                check_ref(roots[k], m_model.nodes.size(), ptr, "node");
                if (m_parent[size_t(roots[k])] != -1)
                    fail(ptr, "node {} is listed as a scene root but is a child of node {}", roots[k],
                         m_parent[size_t(roots[k])]);
                if (listed_in[size_t(roots[k])] == int(s)) fail(ptr, "node {} is listed twice in the scene", roots[k]);
                listed_in[size_t(roots[k])] = int(s);
            }
        }
        if (m_model.defaultScene != -1) check_ref(m_model.defaultScene, m_model.scenes.size(), "/scene", "scene");
    }

    const tinygltf::Model& m_model;
    const std::string& m_file;
    size_t m_max_memory;
    Scene& m_scene;
    std::unordered_map<int, uint32_t> m_max_index;   ///< indices accessor -> largest value
    std::unordered_map<int, bool> m_finite_checked;  ///< accessors already checked for NaN/inf
    std::vector<int> m_parent;                       ///< node -> parent node or -1
    size_t m_line_primitives = 0;
    WarningLog m_warnings;
};

}  // namespace

void validate_gltf(const tinygltf::Model& model, const std::string& file, size_t max_memory, Scene& scene) {
    Validator(model, file, max_memory, scene).run();
}

}  // namespace whitted::gltf
