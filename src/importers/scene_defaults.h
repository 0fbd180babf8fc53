// The default camera and light every importer adds to a scene that has none (private to
// importers/; documented in docs/lights.md).
#pragma once

#include "importers/scene_loader.h"
#include "importers/warning_log.h"
#include "scene/scene.h"

namespace whitted {

/// Appends a perspective camera framing scene.world_bounds() (is_default = true) and records the
/// "default-camera" warning.
void add_default_camera(Scene& scene, WarningLog& warnings);

/// Appends the default directional light (is_default = true) and records the "default-light"
/// warning.
void add_default_light(Scene& scene, WarningLog& warnings);

/// The default camera when the scene has no camera and options.add_default_camera, then the
/// default light when it has no light and options.add_default_light.
void add_scene_defaults(Scene& scene, const ImportOptions& options, WarningLog& warnings);

}  // namespace whitted
