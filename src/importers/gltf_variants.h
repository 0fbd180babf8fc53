// KHR_materials_variants: a file's named material sets (a product configurator's colours). Each
// primitive may map variants to materials other than its own; choosing a variant rewrites the
// primitives' materials in the model before anything reads them (docs/gltf-support.md
// "Material variants").
#pragma once

#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace whitted {

/// The names of the file's variants, in their order (empty without the extension); an unnamed
/// variant is "variant N".
std::vector<std::string> material_variants(const tinygltf::Model& model);

/// Gives every primitive the material its mappings assign to variant `name` (a primitive without a
/// mapping for it keeps its own). Throws whitted::Error naming the file and the problem when the
/// file has no such variant (listing those it has) or a mapping names a material or a variant that
/// does not exist.
void apply_material_variant(tinygltf::Model& model, const std::string& path, const std::string& name);

}  // namespace whitted
