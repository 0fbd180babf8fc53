// A classic scene written out for another run: as a whitted scene file (JSON, docs/scene-format.md)
// and as a POV-Ray 3.7 scene, so that `whitted bench process --vs-povray` can time both programs
// from process start on the same geometry (docs/performance.md, "Against POV-Ray").
//
// Only what the classic scenes use is written: spheres, cylinders, cones and discs, triangle
// meshes (as POV-Ray mesh2), classic materials (constant coefficients or a world-space checker),
// point and directional lights, one perspective camera. Anything else (glTF materials, image
// textures, spot lights, infinite planes, environments) throws whitted::Error naming it: a scene
// that cannot be written faithfully is not written.
//
// The POV-Ray scene maps Whitted's terms onto POV-Ray's finish one to one where they agree
// (Blinn highlight: specular ks, roughness 1/n; reflection kr, no Fresnel; ambient ka times the
// global ambient_light; diffuse kd times the pigment), and approximates where they do not (a
// transmissive surface's pigment carries kt as `transmit`; the inverse-square fall-off is
// POV-Ray's fade_power 2 with a fade_distance far below the scene's distances). Each program is
// judged against its own converged image, so the two need not agree pixel for pixel; they trace
// the same ray trees (max_trace_level = max_depth + 1, adc_bailout = min_weight).
#pragma once

#include <string>

#include "scene/scene.h"

namespace whitted::app {

struct ExportSettings {
    int width = 512, height = 512;
    int max_depth = 5;           ///< the ray tree's depth (camera ray = 0)
    float min_weight = 1.f / 255.f;
    Color ambient{0.05f};        ///< Ia
    Color background{0.f};
};

/// The render settings a scene file gave `scene` (its max_depth, ambient, background; whitted's
/// defaults where it gave none), at width x height.
ExportSettings export_settings(const Scene& scene, int width, int height);

/// `scene` as a whitted scene file (JSON text) with `s`'s render settings.
std::string to_scene_file(const Scene& scene, const ExportSettings& s);

/// `scene` as a POV-Ray 3.7 scene (.pov text) with `s`'s settings.
std::string to_povray(const Scene& scene, const ExportSettings& s);

}  // namespace whitted::app
