// Plain-text description of an imported Scene (`whitted info FILE`).
#pragma once

#include <string>

#include "renderer/scene/scene.h"

namespace whitted {

struct SceneAnalysis;

/// Multi-line report: counts, bounds, scene-file render settings, spheres, infinite planes, lights,
/// cameras, materials (glTF inputs or classic, and the Whitted coefficients), textures (images and
/// procedural checkers), extensions and warnings. One `key: ...` record per line with
/// `name=value` fields, stable across runs, so it can be grepped and diffed. Ends with the scene
/// analysis (describe_analysis, default mapping options).
std::string describe_scene(const Scene& scene);

/// What the renderer may skip for this scene (shading/scene_analysis.h): one `analysis:`
/// line of scene-wide features, one `analysis memory:` line, one `analysis material[i]:` line per
/// material and one `analysis light[i]:` line per light (objects it may reach / all objects).
/// Also printed in the render log.
std::string describe_analysis(const Scene& scene, const SceneAnalysis& analysis);

}  // namespace whitted
