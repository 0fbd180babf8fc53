#include "importers/gltf_variants.h"

#include <fmt/format.h>

#include "core/error.h"
#include "importers/gltf_json.h"
#include "importers/located_error.h"

namespace whitted {

using namespace gltf;

namespace {

constexpr const char* kVariants = "KHR_materials_variants";

}  // namespace

std::vector<std::string> material_variants(const tinygltf::Model& model) {
    std::vector<std::string> names;
    const tinygltf::Value* list = find_member(find_extension(model.extensions, kVariants), "variants");
    for (size_t i = 0; find_element(list, i) != nullptr; ++i) {
        const tinygltf::Value* name = find_member(find_element(list, i), "name");
        names.push_back(name != nullptr && name->IsString() ? name->Get<std::string>() : fmt::format("variant {}", i));
    }
    return names;
}

void apply_material_variant(tinygltf::Model& model, const std::string& path, const std::string& name) {
    const std::vector<std::string> names = material_variants(model);
    if (names.empty())
        throw Error(file_loc(path, ""), fmt::format("variant '{}': the file has no {} variants", name, kVariants));
    size_t chosen = names.size();
    for (size_t i = 0; i < names.size() && chosen == names.size(); ++i)
        if (names[i] == name) chosen = i;
    if (chosen == names.size()) {
        std::string list;
        for (const std::string& n : names) list += (list.empty() ? "'" : ", '") + n + "'";
        throw Error(file_loc(path, "/extensions/KHR_materials_variants/variants"),
                    fmt::format("no variant '{}' (the file has {})", name, list));
    }
    for (size_t m = 0; m < model.meshes.size(); ++m)
        for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
            tinygltf::Primitive& prim = model.meshes[m].primitives[p];
            const tinygltf::Value* mappings = find_member(find_extension(prim.extensions, kVariants), "mappings");
            for (size_t k = 0; find_element(mappings, k) != nullptr; ++k) {
                const std::string ptr =
                    fmt::format("/meshes/{}/primitives/{}/extensions/{}/mappings/{}", m, p, kVariants, k);
                const tinygltf::Value* mapping = find_element(mappings, k);
                int material = -1;
                if (!as_int(find_member(mapping, "material"), material) || material < 0 ||
                    size_t(material) >= model.materials.size())
                    throw Error(file_loc(path, ptr + "/material"),
                                fmt::format("material must be one of the file's {} materials", model.materials.size()));
                const tinygltf::Value* variants = find_member(mapping, "variants");
                bool maps = false;
                for (size_t v = 0; find_element(variants, v) != nullptr; ++v) {
                    int index = -1;
                    if (!as_int(find_element(variants, v), index) || index < 0 || size_t(index) >= names.size())
                        throw Error(file_loc(path, fmt::format("{}/variants/{}", ptr, v)),
                                    fmt::format("variant index must be one of the file's {} variants", names.size()));
                    maps |= size_t(index) == chosen;
                }
                if (maps) prim.material = material;
            }
        }
}

}  // namespace whitted
