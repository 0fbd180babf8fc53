// The generated scene of `whitted bench env`'s occlusion sweep (docs/environment.md, "Occlusion"):
// what a user compares with Blender first. A grey floor (10 x 8, base colour 0.8, rough
// dielectric) and, left to right, a chrome sphere (metal, roughness 0), a rough gold one (metal,
// roughness 0.4), a steel Suzanne (metal, roughness 0.3, assets/gltf/Suzanne at half size), a glass
// sphere (KHR_materials_transmission 1, ior 1.5) and a white diffuse one (base colour 0.9,
// roughness 1), spheres of radius 0.5 resting on the floor; no lights, one perspective camera
// (aspect 4:3). Lit by whatever environment the render names (the furnace: a uniform sky of 1).
#pragma once

#include <cstddef>
#include <filesystem>

namespace whitted::app {

/// Writes the scene as a binary glTF to `path`; returns its triangle count. Throws whitted::Error
/// when Suzanne cannot be read or the file cannot be written.
size_t write_occlusion_scene(const std::filesystem::path& path);

}  // namespace whitted::app
