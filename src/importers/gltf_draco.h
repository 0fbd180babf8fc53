// KHR_draco_mesh_compression (docs/gltf-support.md): primitives whose attributes and indices are
// one Draco stream in a bufferView, decoded with Debian's libdraco into plain bufferViews the rest
// of the importer reads like any other. Private to importers/.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <tiny_gltf.h>

#include "scene/scene.h"

namespace whitted {

/// Before tinygltf parses the file: moves each Draco primitive's `indices` into its extension
/// object (tinygltf refuses an indices accessor without a bufferView, which a Draco primitive's
/// is); decode_draco_primitives() puts it back. True when anything changed.
bool detach_draco_indices(nlohmann::json& doc);

/// After parsing: decodes every Draco stream (in parallel, each once however many primitives
/// share it) and points the primitives' accessors at the decoded data, in new buffers and
/// bufferViews. The accessors' counts and component counts are checked against the stream, its
/// attribute ids against the primitive's attributes (the min/max are checked later with every
/// accessor's). Throws whitted::Error at `path` with the JSON pointer of the primitive's
/// extension. Returns one record per decoded primitive (for `whitted info`).
std::vector<CompressedPrimitive> decode_draco_primitives(tinygltf::Model& model, const std::string& path,
                                                         size_t max_memory);

}  // namespace whitted
