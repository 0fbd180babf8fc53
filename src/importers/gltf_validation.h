// Validation of a parsed glTF model before any of its data is used (private to importers/).
//
// tinygltf checks JSON syntax and a few references; it does not bounds-check accessors, buffer
// views, index values or most references. validate_gltf() checks every object of the file
// (used or not, as glTF-Validator does) and throws whitted::Error naming the file and a JSON
// pointer for the first problem. After it returns, every index, accessor range and reference in
// the model is safe to follow without further checks.
#pragma once

#include <cstddef>
#include <string>

#include <tiny_gltf.h>

#include "scene/scene.h"

namespace whitted::gltf {

/// Checks the whole model; records non-fatal findings (a primitive without POSITION, a
/// TRIANGLES count not a multiple of 3, point/line primitives) with scene.warn().
/// `max_memory` bounds accessors that have no bufferView (implicit zeros).
void validate_gltf(const tinygltf::Model& model, const std::string& file, size_t max_memory, Scene& scene);

/// Number of triangles a primitive of `mode` yields from `n` vertices or indices
/// (TRIANGLES n/3, STRIP and FAN n-2, other modes 0).
size_t triangle_count_for_mode(int mode, size_t n);

/// The accessor glTF says holds a primitive's vertex count: POSITION, else the first attribute.
/// -1 when the primitive has no attributes.
int vertex_count_accessor(const tinygltf::Primitive& primitive);

}  // namespace whitted::gltf
