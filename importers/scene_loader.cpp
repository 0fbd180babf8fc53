// Dispatch on the file extension (case-insensitive).

#include "importers/scene_loader.h"

#include <algorithm>
#include <filesystem>

#include "importers/located_error.h"
#include "importers/scene_file.h"
#include "renderer/core/error.h"

namespace whitted {

Scene load_scene(const std::string& path, const ImportOptions& options) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    Scene scene;
    if (ext == ".gltf" || ext == ".glb") scene = import_gltf(path, options);
    else if (ext == ".json") scene = import_scene_file(path, options);
    else
        throw Error(file_loc(path),
                ext.empty() ? std::string("file has no extension: cannot tell its format (supported: .gltf, .glb, .json)")
                            : "unsupported scene file extension '" + ext + "' (supported: .gltf, .glb, .json)");
    setup_environment(scene, options);
    return scene;
}

}  // namespace whitted
