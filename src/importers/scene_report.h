// Plain-text description of an imported Scene (`whitted info FILE`).
#pragma once

#include <cstddef>
#include <string>

#include "scene/scene.h"

namespace whitted {

struct SceneAnalysis;

/// How much describe_scene prints of lights made from an environment map.
enum class ReportDetail {
    Summary,  ///< the environment's line with the lights' count and share, and the brightest few
    Verbose   ///< also every extracted light and its analysis line
};

/// Extracted environment lights a ReportDetail::Summary lists by name (the most powerful).
constexpr size_t kBrightestEnvironmentLights = 5;

/// Multi-line report: counts, bounds, scene-file render settings, spheres, infinite planes, lights,
/// cameras, materials (glTF inputs or classic, and the Whitted coefficients), textures (images and
/// procedural checkers), extensions and warnings. One `key: ...` record per line with
/// `name=value` fields, stable across runs, so it can be grepped and diffed. Ends with the scene
/// analysis (describe_analysis, default mapping options). Lights extracted from an environment are
/// summarised (`environment light[i]:` lines for the brightest) unless `detail` is Verbose.
std::string describe_scene(const Scene& scene, ReportDetail detail = ReportDetail::Summary);

/// What the renderer may skip for this scene (src/shading/scene_analysis.h): one `analysis:`
/// line of scene-wide features, one `analysis memory:` line, one `analysis material[i]:` line per
/// material and one `analysis light[i]:` line per light (objects it may reach / all objects).
/// Also printed in the render log. Summary leaves out the lights extracted from an environment.
std::string describe_analysis(const Scene& scene, const SceneAnalysis& analysis,
                              ReportDetail detail = ReportDetail::Verbose);

}  // namespace whitted
