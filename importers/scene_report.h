// Plain-text description of an imported Scene (`whitted info FILE`).
#pragma once

#include <string>

#include "renderer/scene/scene.h"

namespace whitted {

/// Multi-line report: counts, bounds, scene-file render settings, spheres, infinite planes, lights,
/// cameras, materials (glTF inputs or classic, and the Whitted coefficients), textures (images and
/// procedural checkers), extensions and warnings. One `key: ...` record per line with
/// `name=value` fields, stable across runs, so it can be grepped and diffed.
std::string describe_scene(const Scene& scene);

}  // namespace whitted
