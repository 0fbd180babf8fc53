// The generated material samples of `whitted bench materials` (material_samples.h): the spheres and
// the floor laid out in one binary buffer, a material per sphere, then the glTF JSON and the GLB
// container (as generated_skin.cpp writes its tube).
#include "benchmarks/material_samples.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/glb_writer.h"
#include "core/error.h"

namespace whitted::app {

namespace {

constexpr int kSpheres = 5;
constexpr int kSegments = 64;     ///< around each sphere
constexpr int kRings = 32;        ///< pole to pole
constexpr double kRadius = 0.5;
constexpr double kSpacing = 1.2;  ///< between sphere centres along x
constexpr double kFloorX = 4.0;   ///< the floor spans x in [-4, 4], z in [kFloorBack, kFloorFront]
constexpr double kFloorBack = -3.0, kFloorFront = 2.0;


/// Sphere k's material (t = k / 4, 0..1) for `extension`, as JSON.
std::string sphere_material(const std::string& extension, int k) {
    const double t = double(k) / double(kSpheres - 1);
    const std::string name = fmt::format("\"name\": \"{} {}\"", extension, k);
    if (extension == "clearcoat")
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_clearcoat\": {{\"clearcoatFactor\": {}, "
                           "\"clearcoatRoughnessFactor\": 0}}}}}}",
                           name, pbr(0.6, 0.05, 0.04, 0.0, 0.6), float(0.2 + 0.8 * t));
    if (extension == "sheen") {
        const double s = 0.2 + 0.8 * t;
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_sheen\": {{\"sheenColorFactor\": [{}, {}, {}], "
                           "\"sheenRoughnessFactor\": {}}}}}}}",
                           name, pbr(0.05, 0.08, 0.3, 0.0, 0.8), float(s), float(0.6 * s), float(0.8 * s),
                           float(0.2 + 0.8 * t));
    }
    if (extension == "iridescence")
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_iridescence\": {{\"iridescenceFactor\": 1, "
                           "\"iridescenceIor\": 1.8, \"iridescenceThicknessMinimum\": 100, "
                           "\"iridescenceThicknessMaximum\": {}}}}}}}",
                           name, pbr(0.02, 0.02, 0.02, 0.0, 0.15), float(200.0 + 600.0 * t));
    if (extension == "anisotropy")
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_anisotropy\": {{\"anisotropyStrength\": {}, "
                           "\"anisotropyRotation\": 0}}}}}}",
                           name, pbr(0.95, 0.8, 0.55, 1.0, 0.4), float(0.2 + 0.8 * t));
    if (extension == "dispersion")
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_transmission\": {{\"transmissionFactor\": 1}}, "
                           "\"KHR_materials_volume\": {{\"thicknessFactor\": 1}}, \"KHR_materials_ior\": {{\"ior\": 1.5}}, "
                           "\"KHR_materials_dispersion\": {{\"dispersion\": {}}}}}}}",
                           name, pbr(1.0, 1.0, 1.0, 0.0, 0.0), float(0.5 + 3.5 * t));
    if (extension == "diffuse_transmission")
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_diffuse_transmission\": "
                           "{{\"diffuseTransmissionFactor\": {}, \"diffuseTransmissionColorFactor\": [1, 0.7, 0.4]}}}}}}",
                           name, pbr(0.8, 0.75, 0.6, 0.0, 0.5), float(0.25 + 0.75 * t));
    if (extension == "specular_glossiness") {
        const double specular = 0.04 + 0.96 * t, glossiness = 0.2 + 0.8 * t;
        return fmt::format("{{{}, {}, \"extensions\": {{\"KHR_materials_pbrSpecularGlossiness\": {{\"diffuseFactor\": "
                           "[0.1, 0.5, 0.15, 1], \"specularFactor\": [{}, {}, {}], \"glossinessFactor\": {}}}}}}}",
                           name, pbr(0.1, 0.5, 0.15, 0.0, 1.0 - glossiness), float(specular), float(specular),
                           float(specular), float(glossiness));
    }
    throw Error(fmt::format("material sample: unknown extension '{}' (available: {})", extension,
                            join(material_sample_extensions(), ", ")));
}

}  // namespace

const std::vector<std::string>& material_sample_extensions() {
    static const std::vector<std::string> names{"clearcoat",  "sheen",
                                                "iridescence", "anisotropy",
                                                "dispersion",  "diffuse_transmission",
                                                "specular_glossiness"};
    return names;
}

std::string material_extension_gltf_name(const std::string& extension) {
    if (extension == "specular_glossiness") return "KHR_materials_pbrSpecularGlossiness";
    return "KHR_materials_" + extension;
}

MaterialSample write_material_sample(const std::filesystem::path& path, const std::string& extension) {
    const std::vector<std::string>& known = material_sample_extensions();
    if (std::find(known.begin(), known.end(), extension) == known.end())
        throw Error(fmt::format("material sample: unknown extension '{}' (available: {})", extension, join(known, ", ")));

    // Geometry: one sphere mesh shared by the 5 sphere meshes (a material each), and the floor.
    GlbLayout l;
    const MeshData sphere = uv_sphere(kRadius, kSegments, kRings), floor = floor_quad(kFloorX, kFloorBack, kFloorFront);
    const std::string sphere_prim = add_mesh(l, sphere), floor_prim = add_mesh(l, floor);
    std::vector<std::string> meshes, materials, nodes;
    for (int k = 0; k < kSpheres; ++k) {
        materials.push_back(sphere_material(extension, k));
        meshes.push_back(fmt::format("{{\"name\": \"sphere {}\", \"primitives\": [{{{}, \"material\": {}}}]}}", k,
                                     sphere_prim, k));
        const double x = kSpacing * (k - (kSpheres - 1) / 2.0);
        nodes.push_back(fmt::format("{{\"name\": \"sphere {}\", \"mesh\": {}, \"translation\": [{}, {}, 0]}}", k, k,
                                    float(x), float(kRadius)));
    }
    materials.push_back(fmt::format("{{\"name\": \"floor\", {}}}", pbr(0.2, 0.2, 0.2, 0.0, 0.9)));
    meshes.push_back(fmt::format("{{\"name\": \"floor\", \"primitives\": [{{{}, \"material\": {}}}]}}", floor_prim, kSpheres));
    nodes.push_back(fmt::format("{{\"name\": \"floor\", \"mesh\": {}}}", kSpheres));

    // The camera: from (0, 1.7, 6.6) towards (0, 0.45, 0), a pitch about +X.
    const double cam_y = 1.7, cam_z = 6.6, target_y = 0.45;
    const double pitch = -std::atan2(cam_y - target_y, cam_z);
    nodes.push_back(fmt::format("{{\"name\": \"camera\", \"camera\": 0, \"translation\": [0, {}, {}], "
                                "\"rotation\": [{}, 0, 0, {}]}}",
                                float(cam_y), float(cam_z), float(std::sin(0.5 * pitch)), float(std::cos(0.5 * pitch))));
    // The light: down and away from the camera, or from behind the row towards it (diffuse transmission).
    const bool behind = extension == "diffuse_transmission";
    double d[3] = {0.35, -0.8, -0.5};
    if (behind) d[0] = -0.2, d[1] = -0.45, d[2] = 0.87;
    const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    nodes.push_back(fmt::format("{{\"name\": \"sun\", \"rotation\": {}, \"extensions\": {{\"KHR_lights_punctual\": "
                                "{{\"light\": 0}}}}}}",
                                rotation_to(d[0] / n, d[1] / n, d[2] / n)));

    std::vector<std::string> used{"\"KHR_lights_punctual\"", fmt::format("\"{}\"", material_extension_gltf_name(extension))};
    if (extension == "dispersion")
        for (const char* e : {"KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"})
            used.push_back(fmt::format("\"{}\"", e));
    const std::string json = scene_json(
        "whitted bench materials (benchmarks/material_samples.cpp)",
        fmt::format(" \"extensionsUsed\": [{}],\n"
                    " \"extensions\": {{\"KHR_lights_punctual\": {{\"lights\": [{{\"name\": \"sun\", \"type\": "
                    "\"directional\", \"intensity\": 2}}]}}}},\n",
                    join(used, ", ")),
        nodes, meshes, materials, 0.72, l);

    const size_t total = write_glb(path, json, l.bin, "material sample");

    MaterialSample out;
    out.triangles = kSpheres * sphere.indices.size() / 3 + floor.indices.size() / 3;
    out.bytes = total;
    return out;
}

}  // namespace whitted::app
