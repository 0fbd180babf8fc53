// EXT_meshopt_compression (docs/gltf-support.md): bufferViews whose bytes are meshoptimizer
// streams in another buffer, decoded into their "fallback" buffer, which carries no data of its
// own. Private to importers/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <tiny_gltf.h>

namespace whitted {

/// The uri given to a fallback buffer without one, so that tinygltf loads it (as `bytes` zeros,
/// served by the importer's file callbacks) instead of refusing a buffer without data.
std::string meshopt_fallback_uri(size_t buffer, size_t bytes);
/// When `lookup` (a path tinygltf asks for) names a fallback buffer: its size.
std::optional<size_t> meshopt_fallback_size(const std::string& lookup);

/// Gives every EXT_meshopt_compression fallback buffer without a uri meshopt_fallback_uri(), in
/// the file's JSON before tinygltf parses it (gltf_compressed.h); true when anything changed.
bool add_meshopt_fallback_uris(nlohmann::json& doc, bool binary);

/// Decodes every bufferView's EXT_meshopt_compression stream (ATTRIBUTES, TRIANGLES, INDICES;
/// filters NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL) into its fallback buffer, after checking
/// every count, stride and byte range (hostile sizes are errors, not allocations). Views of
/// buffers that hold data of their own are left as they are. Throws whitted::Error at `path`
/// with the JSON pointer of the bufferView.
void decode_meshopt_views(tinygltf::Model& model, const std::string& path);

}  // namespace whitted
