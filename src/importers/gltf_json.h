// Safe lookups in tinygltf::Value trees (extension objects tinygltf keeps as raw JSON).
// Private to importers/. tinygltf's own Value::Get asserts on type mismatch; these never do.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <tiny_gltf.h>

#include "importers/located_error.h"

namespace whitted::gltf {

/// The member `key` of an extension map, or nullptr.
inline const tinygltf::Value* find_extension(const tinygltf::ExtensionMap& extensions, std::string_view key) {
    if (extensions.empty()) return nullptr;  // most objects: no std::string key built for the lookup
    auto it = extensions.find(std::string(key));
    return it == extensions.end() ? nullptr : &it->second;
}

/// The member `key` of a JSON object, or nullptr when `object` is not an object or lacks it.
inline const tinygltf::Value* find_member(const tinygltf::Value* object, const std::string& key) {
    if (object == nullptr || !object->IsObject() || !object->Has(key)) return nullptr;
    return &object->Get(key);
}

/// Element `i` of a JSON array, or nullptr.
inline const tinygltf::Value* find_element(const tinygltf::Value* array, size_t i) {
    if (array == nullptr || !array->IsArray() || i >= array->ArrayLen()) return nullptr;
    return &array->Get(int(i));
}

/// True for an integer-valued JSON number that fits an int (tinygltf may store 3 as 3.0).
inline bool as_int(const tinygltf::Value* v, int& out) {
    if (v == nullptr || !v->IsNumber()) return false;
    const double d = v->GetNumberAsDouble();
    if (!(d >= -2147483648.0 && d <= 2147483647.0) || d != double(int(d))) return false;
    out = int(d);
    return true;
}

/// A non-negative integer member of an extension object; `fallback` when absent. Anything else
/// throws whitted::Error at `path`, JSON pointer `ptr`/key.
inline size_t extension_uint(const tinygltf::Value& ext, const char* key, size_t fallback, const std::string& path,
                             const std::string& ptr) {
    const tinygltf::Value* v = find_member(&ext, key);
    if (v == nullptr) return fallback;
    int i = -1;
    if (!as_int(v, i) || i < 0)
        throw Error(file_loc(path, ptr + "/" + key), fmt::format("{} must be a non-negative integer", key));
    return size_t(i);
}

/// A string member of an extension object; `fallback` when absent or not a string.
inline std::string extension_text(const tinygltf::Value& ext, const char* key, const char* fallback) {
    const tinygltf::Value* v = find_member(&ext, key);
    return v != nullptr && v->IsString() ? v->Get<std::string>() : std::string(fallback);
}

}  // namespace whitted::gltf
