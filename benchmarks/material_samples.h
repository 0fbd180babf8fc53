// Generated glTF samples for `whitted bench materials`: one small scene per material extension,
// for the extensions without a bundled sample (and as the fallback of those with one).
//
// Every sample is the same scene: a row of 5 UV spheres (radius 0.5, 64 x 32 segments, with
// NORMAL, TEXCOORD_0 and TANGENT) resting on a grey floor quad (8 x 5, the same attributes), one
// KHR_lights_punctual directional light and a perspective camera (aspect 4:3) framing the row.
// Sphere k (0..4, left to right) uses the extension at strength t = k / 4:
//   clearcoat             red rough base, clearcoatFactor 0.2..1, clearcoatRoughness 0
//   sheen                 dark blue rough base, sheenColor (0.2..1) x (1, 0.6, 0.8), sheenRoughness 0.2..1
//   iridescence           black dielectric (roughness 0.15), iridescenceFactor 1, film ior 1.8, thickness 200..800 nm
//   anisotropy            metal (roughness 0.4), anisotropyStrength 0.2..1 along the tangent
//   dispersion            glass: transmission 1, KHR_materials_volume thickness 1, ior 1.5, dispersion 0.5..4
//   diffuse_transmission  warm rough base, diffuseTransmissionFactor 0.25..1; the light comes from behind
//   specular_glossiness   green diffuse, specularFactor 0.04..1 (grey), glossinessFactor 0.2..1, with a
//                         pbrMetallicRoughness fallback (metallic 0, roughness 1 - glossiness)
// The light travels down and away from the camera, except for diffuse_transmission, where it comes
// from behind the row towards the camera. Everything is a function of the extension: the same
// name writes the same bytes.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace whitted::app {

/// The extensions with a generated sample, in the bench's order (the names `--only` takes).
const std::vector<std::string>& material_sample_extensions();

/// The glTF extension name of a sample name: "clearcoat" -> "KHR_materials_clearcoat",
/// "specular_glossiness" -> "KHR_materials_pbrSpecularGlossiness".
std::string material_extension_gltf_name(const std::string& extension);

/// What write_material_sample wrote.
struct MaterialSample {
    size_t triangles = 0;  ///< spheres and floor
    size_t bytes = 0;      ///< size of the file
};

/// Writes the sample of `extension` (one of material_sample_extensions()) as a binary glTF (.glb)
/// to `path`; throws whitted::Error for an unknown extension or when the file cannot be written.
MaterialSample write_material_sample(const std::filesystem::path& path, const std::string& extension);

}  // namespace whitted::app
