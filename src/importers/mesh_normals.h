// Vertex normals for meshes that come without them: used by the importers (a glTF primitive with
// no NORMAL, scene-file inline meshes) and by programs that build meshes in code.
#pragma once

#include <vector>

#include "scene/scene.h"

namespace whitted {

/// Area-weighted smooth vertex normals: the sum of the (unnormalized) face normals of every
/// triangle using the vertex, normalized; +Z where the sum vanishes.
std::vector<Vec3f> smooth_normals(const Mesh& mesh);

}  // namespace whitted
