// The whitted scene file: JSON that composes glTF files with analytic primitives (spheres,
// planes), boxes, inline meshes, Whitted's (1980) materials, lights, a camera and render
// settings (docs/scene-format.md, schema docs/scene-format.schema.json).
#pragma once

#include <string>
#include <string_view>

#include "importers/scene_loader.h"
#include "scene/scene.h"

namespace whitted {

/// Current (and only) value of the file's "version" key.
constexpr int kSceneFileVersion = 1;

/// Reads a scene file (.json). Throws whitted::Error naming the file, the JSON pointer of the
/// offending value and its line:column. Includes and image textures resolve relative to the
/// file's folder; `options.scene_index` is not used (each include has its own "scene").
Scene import_scene_file(const std::string& path, const ImportOptions& options = {});

/// The same from text in memory; `path` names the source in errors and its folder anchors
/// relative paths (includes, image textures).
Scene import_scene_file_text(std::string_view text, const std::string& path, const ImportOptions& options = {});

}  // namespace whitted
