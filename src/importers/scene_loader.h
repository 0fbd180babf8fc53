// Importers turn files into a validated, plain Scene or throw one whitted::Error naming the file
// and the problem (with a JSON pointer such as /accessors/3 where one applies).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "scene/environment.h"
#include "scene/scene.h"
#include "scene/scene_update.h"

namespace whitted {

struct ImportOptions {
    int scene_index = -1;                       ///< glTF scene to load; -1 = the file's default (or 0)
    size_t max_memory = size_t(8) << 30;        ///< bytes the imported data may take before it is refused
    bool add_default_light = true;              ///< a scene without lights gets the documented default
    bool add_default_camera = true;             ///< a scene without cameras gets one framing its bounds
    bool load_textures = true;                  ///< false: skip image decoding (faster `info`)
    bool allow_outside_uris = false;            ///< external URIs may leave the file's folder ("../");
                                                ///< absolute and file:// URIs are refused either way
    // The environment (docs/environment.md): what rays that leave the scene see, and its light.
    std::string environment;                    ///< lat-long map (file or bundled name) replacing the scene's;
                                                ///< empty = the scene file's, if any
    std::optional<float> environment_rotation;  ///< degrees about +Y; unset = the scene file's (or 0)
    std::optional<float> environment_exposure;  ///< stops; unset = the scene file's (or 0)
    bool no_environment = false;                ///< no environment at all, whatever the file says
    bool default_environment = true;            ///< a glTF file with no lights and no environment is lit
                                                ///< by the bundled studio map instead of the default light
    int environment_lights = kDefaultEnvironmentLights;  ///< lights extracted from it (0 = all of its light is ambient)
    // Animation (docs/gltf-support.md "Animation"): the moment a glTF file is posed at.
    double time = 0.0;                          ///< seconds; finite, >= 0
    std::string animation = "all";              ///< "all", a name, or indices "0,2": the animations applied
    bool loop = false;                          ///< each animation repeats after its duration (else it holds its last key)
    // Materials (docs/gltf-support.md "Material variants").
    std::string variant;                        ///< a KHR_materials_variants variant by name; empty = the default materials
};

/// The default camera of a scene without one (docs/lights.md): perspective, looking at the centre
/// of `bounds` from 15 degrees above, far enough to frame them; turned about +Y through the centre by
/// `orbit_degrees` (a turntable).
Camera default_camera(const Bounds3d& bounds, double orbit_degrees = 0.0);

/// Throws whitted::Error unless `time` is a finite number of seconds >= 0 (`what` names it: "--time").
void check_animation_time(double time, const std::string& what);

/// Sets up the scene's environment after import: the one `options` names replaces the file's
/// (rotation and exposure overrides apply to either), then its light is split into directional
/// lights (appended to scene.lights, replacing the default light) and the SH ambient. Throws
/// whitted::Error for a map that cannot be read.
void setup_environment(Scene& scene, const ImportOptions& options);

/// Every option the imported scene depends on, by name (as describe_image_settings for the
/// render settings): what checkpoints and tile-job parts record.
std::vector<std::pair<std::string, std::string>> describe_import_options(const ImportOptions& options);

/// Loads a scene, dispatching on the extension: .gltf, .glb (import_gltf), .json (the scene file,
/// import_scene_file in src/importers/scene_file.h).
Scene load_scene(const std::string& path, const ImportOptions& options = {});

/// A scene loaded once and posed again at other moments in place (the frames of a sequence): only
/// what an animation moves is rewritten (scene/scene_update.h).
class SceneAnimator {
public:
    virtual ~SceneAnimator() = default;
    /// Poses `scene` (the one load_animated_scene returned, as the last call left it) at `time`
    /// seconds: afterwards it is what load_scene at that time returns, and the result says what
    /// changed. A glTF file is posed from the model kept in memory; a scene file, and a glTF file
    /// whose node graph changes its structure (a transform turns mirroring), are loaded again
    /// (SceneUpdate::reloaded). Throws whitted::Error as load_scene does.
    virtual SceneUpdate pose(Scene& scene, double time) = 0;
};

struct AnimatedScene {
    Scene scene;
    std::unique_ptr<SceneAnimator> animator;
};

/// load_scene, keeping what it needs to pose the scene again at other times.
AnimatedScene load_animated_scene(const std::string& path, const ImportOptions& options = {});

/// glTF 2.0 (.gltf with external or data-URI resources, .glb).
Scene import_gltf(const std::string& path, const ImportOptions& options = {});

/// glTF 2.0 from bytes in memory (JSON, or GLB when `path` ends in .glb or the bytes start with
/// the GLB magic). `path` names the source in errors; its folder anchors relative URIs.
Scene import_gltf_memory(std::span<const uint8_t> bytes, const std::string& path, const ImportOptions& options = {});

/// import_gltf keeping the parsed file to pose it again (the environment is load_scene's part).
AnimatedScene import_gltf_animated(const std::string& path, const ImportOptions& options = {});

}  // namespace whitted
