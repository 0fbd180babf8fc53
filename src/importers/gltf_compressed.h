// Compressed glTF (docs/gltf-support.md): the one JSON pass before tinygltf parses a file that
// uses KHR_draco_mesh_compression or EXT_meshopt_compression, and what `whitted info` reports of
// the compressed primitives. Private to importers/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <tiny_gltf.h>

#include "scene/scene.h"

namespace whitted {

/// The file made ready for tinygltf: meshopt fallback buffers get a uri (gltf_meshopt.h), Draco
/// primitives' indices move into their extension (gltf_draco.h), and KHR_animation_pointer channel
/// targets get the `"node": -1` tinygltf 2.7 requires of every target (its pointer stays in the
/// target's extension). nullopt when none applies (the file is used as it is). `json` is the
/// file's JSON (all of it, or a GLB's JSON chunk at `json_offset`); a GLB comes back as a GLB,
/// its other chunks unchanged.
std::optional<std::vector<uint8_t>> prepare_for_tinygltf(std::span<const uint8_t> file, bool binary,
                                                         size_t json_offset, size_t json_size);

/// One record per primitive whose accessors read EXT_meshopt_compression bufferViews: the
/// streams' bytes against the decoded bytes of those views.
std::vector<CompressedPrimitive> meshopt_primitives(const tinygltf::Model& model);

}  // namespace whitted
