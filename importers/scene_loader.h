// Importers turn files into a validated, plain Scene or throw one whitted::Error naming the file
// and the problem (with a JSON pointer such as /accessors/3 where one applies).
#pragma once

#include <cstddef>
#include <string>

#include "renderer/scene/scene.h"

namespace whitted {

struct ImportOptions {
    int scene_index = -1;                       ///< glTF scene to load; -1 = the file's default (or 0)
    size_t max_memory = size_t(8) << 30;        ///< bytes the imported data may take before it is refused
    bool add_default_light = true;              ///< a scene without lights gets the documented default
    bool add_default_camera = true;             ///< a scene without cameras gets one framing its bounds
    bool load_textures = true;                  ///< false: skip image decoding (faster `info`)
};

/// Loads a scene, dispatching on the extension (.gltf, .glb).
Scene load_scene(const std::string& path, const ImportOptions& options = {});

/// glTF 2.0 (.gltf with external or data-URI resources, .glb).
Scene import_gltf(const std::string& path, const ImportOptions& options = {});

}  // namespace whitted
