// Dispatch on the file extension (case-insensitive).

#include "importers/scene_loader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "importers/environment_image.h"
#include "importers/located_error.h"
#include "importers/scene_file.h"
#include "core/error.h"
#include "core/log.h"

namespace whitted {

std::vector<std::pair<std::string, std::string>> describe_import_options(const ImportOptions& o) {
    auto num = [](const std::optional<float>& v) { return v ? fmt::format("{:.9g}", *v) : std::string("file"); };
    auto flag = [](bool b) { return std::string(b ? "on" : "off"); };
    return {{"scene_index", std::to_string(o.scene_index)},
            {"default_light", flag(o.add_default_light)},
            {"default_camera", flag(o.add_default_camera)},
            {"textures", flag(o.load_textures)},
            {"environment", o.environment.empty() ? "file" : o.environment},
            {"env_rotate", num(o.environment_rotation)},
            {"env_exposure", num(o.environment_exposure)},
            {"no_environment", flag(o.no_environment)},
            {"default_environment", flag(o.default_environment)},
            {"env_lights", std::to_string(o.environment_lights)},
            {"time", fmt::format("{:.17g}", o.time)},
            {"animation", o.animation},
            {"loop", flag(o.loop)}};
}

void check_animation_time(double time, const std::string& what) {
    if (!std::isfinite(time) || time < 0.0)
        throw Error(fmt::format("{} {}: expected a finite number of seconds, 0 or more", what, time));
}

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
    // A glTF file with neither lights nor an environment is lit by the bundled studio map, as
    // glTF viewers do (docs/environment.md); its lights replace the default light.
    const bool unlit = std::all_of(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return l.is_default; });
    if (ext != ".json" && unlit && !scene.environment && options.environment.empty() && options.default_environment &&
        !options.no_environment) {
        ImportOptions with_studio = options;
        with_studio.environment = bundled_environment_names().front();
        log_info("{}: no lights and no environment in the file: lit by the bundled '{}' environment "
                 "(--no-environment: the default light instead)",
                 path, with_studio.environment);
        setup_environment(scene, with_studio);
        return scene;
    }
    setup_environment(scene, options);
    return scene;
}

}  // namespace whitted
