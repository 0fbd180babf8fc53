// RenderSettings: everything a render takes besides the scene, and the one place where a scene
// file's render settings merge with the caller's (command line, Python): what the caller set wins.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "film/film.h"
#include "integrator/aa_sampler.h"
#include "integrator/whitted_integrator.h"
#include "scene/scene.h"
#include "shading/material_mapping.h"

namespace whitted {

struct RenderSettings {
    int width = 0, height = 0;            ///< pixels; 0 = from the camera's aspect ratio (default 640 wide)
    int camera = 0;                       ///< index into Scene::cameras
    IntegratorSettings integrator;        ///< depth, background, ambient, fresnel
    MappingOptions mapping;               ///< glTF -> Whitted mapping options
    float exposure = 1.f;                 ///< linear scale applied to the radiance (2^stops from the CLI)
    int tile_size = 32;                   ///< square tiles of this many pixels
    int threads = 0;                      ///< 0 = all hardware threads
    std::optional<PixelWindow> crop;      ///< render only this region of the full image
    AovSet aovs;                          ///< extra outputs from the pixel-centre camera ray
    AaSettings aa;                        ///< anti-aliasing mode and its parameters
    std::string accel = "embree";         ///< accelerator backend
    bool robust = true;                   ///< Embree ROBUST mode: watertight at edges (docs/numerical-stability.md section 3)
    bool progress = false;                ///< progress bar with ETA on stderr (when it is a terminal)
};

/// The settings `whitted render` and the Python module start from: adaptive anti-aliasing, the
/// adaptive tree depth at min_weight 1/255 and the progress bar (RenderSettings' own defaults
/// are one centre ray per pixel, the depth limit only and no bar).
RenderSettings command_line_render_settings();

/// "r,g,b" or a single gray value; throws whitted::Error naming `what` (a flag) otherwise.
Color parse_color(const std::string& text, const char* what);

/// An --env-occlusion value: "off" (or 0) turns occlusion off, an integer 1..kMaxEnvOcclusion is
/// the directions per point; throws whitted::Error naming `what` otherwise.
int parse_env_occlusion(const std::string& text, const char* what);

/// AOV names (depth/z, normal/n, albedo, primid, instid, aa_samples, all) as an AovSet; throws
/// whitted::Error naming the unknown one and the choices.
AovSet parse_aovs(const std::vector<std::string>& names);

/// Fills every setting of `rs` the caller did not set (`given`) from a scene file's settings `s`
/// (size, camera, anti-aliasing, depth, min weight, background, ambient, exposure in stops,
/// Fresnel); what the file leaves unset keeps `rs`. An ambient from the file or the caller turns the
/// environment's ambient off; a background from the caller hides the environment from camera rays.
/// Image size (docs/cli.md, "Image size"; 0 = not set): a width or height set alone keeps the file's aspect ratio when the file gives both, else
/// the other becomes 0 (the camera's aspect completes it). Output path, OCIO view and display
/// belong to the output stage (apply_scene_output_settings).
void apply_scene_settings(const SceneRenderSettings& s, RenderSettings& rs, const SettingGiven& given = {});

/// A setting's name and its value as text, exact (floats to 9 significant digits).
using SettingList = std::vector<std::pair<std::string, std::string>>;

/// Every setting of `rs` the rendered pixels depend on (not threads or the progress bar), by
/// name: what a checkpoint and the parts of a tile job record, so that a resume or a merge can
/// refuse pieces made otherwise and say which setting differs.
SettingList describe_image_settings(const RenderSettings& rs);

}  // namespace whitted
