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
            {"loop", flag(o.loop)},
            {"variant", o.variant.empty() ? "default" : o.variant}};
}

void check_animation_time(double time, const std::string& what) {
    if (!std::isfinite(time) || time < 0.0)
        throw Error(fmt::format("{} {}: expected a finite number of seconds, 0 or more", what, time));
}

namespace {

/// The file's extension, lower case; throws for one no importer reads.
std::string scene_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb" || ext == ".json") return ext;
    throw Error(file_loc(path),
                ext.empty() ? std::string("file has no extension: cannot tell its format (supported: .gltf, .glb, .json)")
                            : "unsupported scene file extension '" + ext + "' (supported: .gltf, .glb, .json)");
}

/// What load_scene does after the importer: the environment.
void finish_scene(Scene& scene, const std::string& path, const std::string& ext, const ImportOptions& options) {
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
        return;
    }
    setup_environment(scene, options);
}

/// A scene file posed by loading it again at each time.
class ReloadAnimator final : public SceneAnimator {
public:
    ReloadAnimator(std::string path, ImportOptions options) : m_path(std::move(path)), m_options(std::move(options)) {}
    SceneUpdate pose(Scene& scene, double time) override {
        ImportOptions at = m_options;
        at.time = time;
        scene = load_scene(m_path, at);
        SceneUpdate u;
        u.reloaded = true;
        return u;
    }

private:
    std::string m_path;
    ImportOptions m_options;
};

/// A variant names a glTF file's materials: a scene file names one per include instead.
void check_variant(const std::string& path, const std::string& ext, const ImportOptions& options) {
    if (ext == ".json" && !options.variant.empty())
        throw Error(file_loc(path, ""), fmt::format("variant '{}': a scene file has no variants; name one per "
                                                    "included glTF file (\"variant\" in its include)",
                                                    options.variant));
}

}  // namespace

Scene load_scene(const std::string& path, const ImportOptions& options) {
    const std::string ext = scene_extension(path);
    check_variant(path, ext, options);
    Scene scene = ext == ".json" ? import_scene_file(path, options) : import_gltf(path, options);
    finish_scene(scene, path, ext, options);
    return scene;
}

AnimatedScene load_animated_scene(const std::string& path, const ImportOptions& options) {
    const std::string ext = scene_extension(path);
    check_variant(path, ext, options);
    AnimatedScene a;
    if (ext == ".json") {
        a.scene = import_scene_file(path, options);
        a.animator = std::make_unique<ReloadAnimator>(path, options);
    } else {
        a = import_gltf_animated(path, options);
    }
    finish_scene(a.scene, path, ext, options);
    return a;
}

}  // namespace whitted
