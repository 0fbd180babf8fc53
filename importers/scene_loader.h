// Importers turn files into a validated, plain Scene or throw one whitted::Error naming the file
// and the problem (with a JSON pointer such as /accessors/3 where one applies).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "renderer/scene/scene.h"

namespace whitted {

struct ImportOptions {
    int scene_index = -1;                       ///< glTF scene to load; -1 = the file's default (or 0)
    size_t max_memory = size_t(8) << 30;        ///< bytes the imported data may take before it is refused
    bool add_default_light = true;              ///< a scene without lights gets the documented default
    bool add_default_camera = true;             ///< a scene without cameras gets one framing its bounds
    bool load_textures = true;                  ///< false: skip image decoding (faster `info`)
    bool allow_outside_uris = false;            ///< external URIs may leave the file's folder ("../");
                                                ///< absolute and file:// URIs are refused either way
};

/// Loads a scene, dispatching on the extension: .gltf, .glb (import_gltf), .json (the scene file,
/// import_scene_file in importers/scene_file.h).
Scene load_scene(const std::string& path, const ImportOptions& options = {});

/// glTF 2.0 (.gltf with external or data-URI resources, .glb).
Scene import_gltf(const std::string& path, const ImportOptions& options = {});

/// glTF 2.0 from bytes in memory (JSON, or GLB when `path` ends in .glb or the bytes start with
/// the GLB magic). `path` names the source in errors; its folder anchors relative URIs.
Scene import_gltf_memory(std::span<const uint8_t> bytes, const std::string& path, const ImportOptions& options = {});

}  // namespace whitted
