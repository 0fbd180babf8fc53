// Typed reading of glTF accessors (private to importers/).
//
// tinygltf parses accessors but does not bounds-check them. Everything here assumes the accessor
// has passed validate_gltf() (gltf_validation.h): no function re-checks ranges. Reading decodes
// every component type (normalized or not, KHR_mesh_quantization) and applies sparse
// substitution, calling a visitor once per dense element and then once per sparse override.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include <tiny_gltf.h>

namespace whitted::gltf {

// glTF component type codes (glTF 2.0 spec, accessor.componentType).
constexpr int kByte = 5120;
constexpr int kUnsignedByte = 5121;
constexpr int kShort = 5122;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kFloat = 5126;

/// Bytes of one component; 0 for a component type glTF 2.0 does not allow (INT, DOUBLE, junk).
int component_size(int component_type);
/// Components of an accessor type (SCALAR 1 ... MAT4 16); 0 for an unknown type.
int component_count(int type);
/// Name of an accessor type or component type for messages ("VEC3", "UNSIGNED_SHORT").
const char* type_name(int type);
const char* component_type_name(int component_type);
/// Bytes of one element, including the column padding matrices of 1- and 2-byte components need.
size_t element_size(int component_type, int type);

/// Where an accessor's bytes are. Valid only for validated accessors.
struct AccessorData {
    const uint8_t* base = nullptr;  ///< first dense element; nullptr = no bufferView (all zeros)
    size_t stride = 0;              ///< bytes between dense elements
    size_t count = 0;               ///< elements
    int component_type = 0;
    int components = 0;  ///< 1..4 for SCALAR..VEC4 (matrices are never read)
    bool normalized = false;
    size_t sparse_count = 0;  ///< 0 = not sparse
    const uint8_t* sparse_indices = nullptr;
    int sparse_index_type = 0;               ///< kUnsignedByte / kUnsignedShort / kUnsignedInt
    const uint8_t* sparse_values = nullptr;  ///< tightly packed elements
};

/// Locates accessor `index` (already validated) in the model's buffers.
AccessorData accessor_data(const tinygltf::Model& model, int index);

namespace detail {

template <typename T>
inline T load(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));  // glTF is little-endian, like every platform whitted builds on
    return v;
}

/// A component as float: normalized integers per glTF 2.0 "Animations / normalized" rules
/// (signed: max(c / MAX, -1); unsigned: c / MAX), other integers converted as they are.
template <typename T>
inline float to_float(T c, bool normalized) {
    if constexpr (std::is_same_v<T, float>) {
        return c;
    } else {
        if (!normalized) return float(c);
        constexpr float max_value = float(std::numeric_limits<T>::max());
        if constexpr (std::is_signed_v<T>)
            return std::max(float(c) / max_value, -1.f);
        else
            return float(c) / max_value;
    }
}

inline uint32_t load_index(const uint8_t* p, int component_type) {
    switch (component_type) {
        case kUnsignedByte:
            return *p;
        case kUnsignedShort:
            return load<uint16_t>(p);
        default:
            return load<uint32_t>(p);
    }
}

/// A component as double, exactly as stored (accessor min/max are compared on stored values).
template <typename T>
inline double to_raw(T c) {
    return double(c);
}

template <typename T, bool Raw, typename Visitor>
void visit_typed(const AccessorData& a, Visitor&& visit) {
    using Out = std::conditional_t<Raw, double, float>;
    Out v[16] = {};  // up to MAT4 (skins' inverse bind matrices)
    const int n = a.components;
    auto decode = [&](const uint8_t* p) {
        for (int c = 0; c < n; ++c) {
            const T x = load<T>(p + size_t(c) * sizeof(T));
            if constexpr (Raw)
                v[c] = to_raw(x);
            else
                v[c] = to_float(x, a.normalized);
        }
    };
    if (a.base == nullptr) {
        for (size_t i = 0; i < a.count; ++i) visit(i, static_cast<const Out*>(v));
    } else {
        const uint8_t* p = a.base;
        for (size_t i = 0; i < a.count; ++i, p += a.stride) {
            decode(p);
            visit(i, static_cast<const Out*>(v));
        }
    }
    // Sparse substitution: the overriding values are tightly packed.
    const size_t isize = a.sparse_index_type == kUnsignedByte ? 1 : a.sparse_index_type == kUnsignedShort ? 2 : 4;
    for (size_t j = 0; j < a.sparse_count; ++j) {
        const uint32_t i = load_index(a.sparse_indices + j * isize, a.sparse_index_type);
        decode(a.sparse_values + j * size_t(n) * sizeof(T));
        visit(size_t(i), static_cast<const Out*>(v));
    }
}

template <bool Raw, typename Visitor>
void visit_any(const AccessorData& a, Visitor&& visit) {
    switch (a.component_type) {
        case kByte:
            visit_typed<int8_t, Raw>(a, visit);
            break;
        case kUnsignedByte:
            visit_typed<uint8_t, Raw>(a, visit);
            break;
        case kShort:
            visit_typed<int16_t, Raw>(a, visit);
            break;
        case kUnsignedShort:
            visit_typed<uint16_t, Raw>(a, visit);
            break;
        case kUnsignedInt:
            visit_typed<uint32_t, Raw>(a, visit);
            break;
        default:
            visit_typed<float, Raw>(a, visit);
            break;
    }
}

}  // namespace detail

/// Calls visit(size_t element, const float* values) for every element (values has
/// `a.components` entries, normalized when the accessor says so), then again for every sparse
/// override, so a visitor that stores by element index ends with the substituted data.
template <typename Visitor>
void for_each_element(const AccessorData& a, Visitor&& visit) {
    detail::visit_any<false>(a, visit);
}

/// Like for_each_element but visit(size_t, const double*) gets the numbers as stored, without
/// normalization (the semantics of accessor.min / accessor.max).
template <typename Visitor>
void for_each_raw_element(const AccessorData& a, Visitor&& visit) {
    detail::visit_any<true>(a, visit);
}

/// Calls visit(size_t element, uint32_t value) for an unsigned SCALAR accessor (indices,
/// sparse indices), then for every sparse override.
template <typename Visitor>
void for_each_index(const AccessorData& a, Visitor&& visit) {
    const size_t csize = size_t(component_size(a.component_type));
    if (a.base == nullptr) {
        for (size_t i = 0; i < a.count; ++i) visit(i, uint32_t(0));
    } else {
        const uint8_t* p = a.base;
        switch (a.component_type) {
            case kUnsignedByte:
                for (size_t i = 0; i < a.count; ++i, p += a.stride) visit(i, uint32_t(*p));
                break;
            case kUnsignedShort:
                for (size_t i = 0; i < a.count; ++i, p += a.stride) visit(i, uint32_t(detail::load<uint16_t>(p)));
                break;
            default:
                for (size_t i = 0; i < a.count; ++i, p += a.stride) visit(i, detail::load<uint32_t>(p));
                break;
        }
    }
    const size_t isize = size_t(component_size(a.sparse_index_type));
    for (size_t j = 0; j < a.sparse_count; ++j) {
        const uint32_t i = detail::load_index(a.sparse_indices + j * isize, a.sparse_index_type);
        visit(size_t(i), detail::load_index(a.sparse_values + j * csize, a.component_type));
    }
}

}  // namespace whitted::gltf
