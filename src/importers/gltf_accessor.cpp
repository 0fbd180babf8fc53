// Accessor layout arithmetic (glTF 2.0 spec, "Accessors" and "Data alignment").

#include "importers/gltf_accessor.h"

namespace whitted::gltf {

int component_size(int component_type) {
    switch (component_type) {
        case kByte:
        case kUnsignedByte:
            return 1;
        case kShort:
        case kUnsignedShort:
            return 2;
        case kUnsignedInt:
        case kFloat:
            return 4;
        default:
            return 0;  // INT (5124) and DOUBLE (5130) are not glTF 2.0 component types
    }
}

int component_count(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
            return 4;
        case TINYGLTF_TYPE_MAT2:
            return 4;
        case TINYGLTF_TYPE_MAT3:
            return 9;
        case TINYGLTF_TYPE_MAT4:
            return 16;
        default:
            return 0;
    }
}

const char* type_name(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return "SCALAR";
        case TINYGLTF_TYPE_VEC2:
            return "VEC2";
        case TINYGLTF_TYPE_VEC3:
            return "VEC3";
        case TINYGLTF_TYPE_VEC4:
            return "VEC4";
        case TINYGLTF_TYPE_MAT2:
            return "MAT2";
        case TINYGLTF_TYPE_MAT3:
            return "MAT3";
        case TINYGLTF_TYPE_MAT4:
            return "MAT4";
        default:
            return "unknown type";
    }
}

const char* component_type_name(int component_type) {
    switch (component_type) {
        case kByte:
            return "BYTE";
        case kUnsignedByte:
            return "UNSIGNED_BYTE";
        case kShort:
            return "SHORT";
        case kUnsignedShort:
            return "UNSIGNED_SHORT";
        case kUnsignedInt:
            return "UNSIGNED_INT";
        case kFloat:
            return "FLOAT";
        default:
            return "unknown component type";
    }
}

size_t element_size(int component_type, int type) {
    const size_t c = size_t(component_size(component_type));
    // Matrix columns start on 4-byte boundaries: MAT2/MAT3 of 1-byte and MAT3 of 2-byte
    // components carry padding (spec 3.6.2.4, "Data alignment").
    if (type == TINYGLTF_TYPE_MAT2 && c == 1) return 8;
    if (type == TINYGLTF_TYPE_MAT3 && c == 1) return 12;
    if (type == TINYGLTF_TYPE_MAT3 && c == 2) return 24;
    return c * size_t(component_count(type));
}

AccessorData accessor_data(const tinygltf::Model& model, int index) {
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    AccessorData d;
    d.count = a.count;
    d.component_type = a.componentType;
    d.components = component_count(a.type);
    d.normalized = a.normalized;
    const size_t elem = element_size(a.componentType, a.type);
    if (a.bufferView >= 0) {
        const tinygltf::BufferView& bv = model.bufferViews[size_t(a.bufferView)];
        d.base = model.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + a.byteOffset;
        d.stride = bv.byteStride != 0 ? bv.byteStride : elem;
    }
    if (a.sparse.isSparse) {
        const tinygltf::BufferView& ibv = model.bufferViews[size_t(a.sparse.indices.bufferView)];
        const tinygltf::BufferView& vbv = model.bufferViews[size_t(a.sparse.values.bufferView)];
        d.sparse_count = size_t(a.sparse.count);
        d.sparse_index_type = a.sparse.indices.componentType;
        d.sparse_indices =
            model.buffers[size_t(ibv.buffer)].data.data() + ibv.byteOffset + size_t(a.sparse.indices.byteOffset);
        d.sparse_values =
            model.buffers[size_t(vbv.buffer)].data.data() + vbv.byteOffset + size_t(a.sparse.values.byteOffset);
    }
    return d;
}

}  // namespace whitted::gltf
