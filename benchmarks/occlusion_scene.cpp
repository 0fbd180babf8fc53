// The occlusion scene of `whitted bench env` (occlusion_scene.h).
#include "benchmarks/occlusion_scene.h"

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/glb_writer.h"
#include "core/error.h"
#include "importers/scene_loader.h"

namespace whitted::app {

namespace {

constexpr double kRadius = 0.5;
constexpr double kSuzanneScale = 0.5;

/// Suzanne's first mesh (POSITION, NORMAL) from the bundled copy.
MeshData suzanne() {
    const std::filesystem::path file =
        std::filesystem::path(WHITTED_SOURCE_DIR) / "assets" / "gltf" / "Suzanne" / "glTF-Binary" / "Suzanne.glb";
    ImportOptions io;
    io.no_environment = true;
    io.add_default_light = false;
    const Scene scene = load_scene(file.string(), io);
    if (scene.meshes.empty()) throw Error(fmt::format("{}: no mesh", file.string()));
    const Mesh& m = scene.meshes.front();
    MeshData out;
    for (size_t v = 0; v < m.positions.size(); ++v) {
        out.positions.insert(out.positions.end(), {m.positions[v].x, m.positions[v].y, m.positions[v].z});
        out.normals.insert(out.normals.end(), {m.normals[v].x, m.normals[v].y, m.normals[v].z});
    }
    out.indices = m.indices;
    return out;
}

}  // namespace

size_t write_occlusion_scene(const std::filesystem::path& path) {
    GlbLayout l;
    const MeshData sphere = uv_sphere(kRadius, 64, 32), floor = floor_quad(5.0, -4.0, 4.0), monkey = suzanne();
    const std::string sphere_prim = add_mesh(l, sphere), floor_prim = add_mesh(l, floor),
                      monkey_prim = add_mesh(l, monkey);
    float monkey_min_y = 0.f;
    for (size_t v = 0; v < monkey.vertices(); ++v) monkey_min_y = std::min(monkey_min_y, monkey.positions[3 * v + 1]);

    struct Object {
        const char* name;
        std::string material;  // JSON members after the name
        const std::string* prim;
        double x, y, scale;
    };
    const std::vector<Object> objects{
        {"chrome", pbr(0.95, 0.95, 0.95, 1.0, 0.0), &sphere_prim, -2.4, kRadius, 1.0},
        {"rough gold", pbr(1.0, 0.766, 0.336, 1.0, 0.4), &sphere_prim, -1.2, kRadius, 1.0},
        {"steel", pbr(0.56, 0.57, 0.58, 1.0, 0.3), &monkey_prim, 0.0, -double(monkey_min_y) * kSuzanneScale, kSuzanneScale},
        {"glass",
         pbr(1.0, 1.0, 1.0, 0.0, 0.0) +
             ", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, "
             "\"KHR_materials_ior\": {\"ior\": 1.5}}",
         &sphere_prim, 1.2, kRadius, 1.0},
        {"white", pbr(0.9, 0.9, 0.9, 0.0, 1.0), &sphere_prim, 2.4, kRadius, 1.0},
        {"floor", pbr(0.8, 0.8, 0.8, 0.0, 0.9), &floor_prim, 0.0, 0.0, 1.0},
    };
    std::vector<std::string> meshes, materials, nodes;
    for (size_t k = 0; k < objects.size(); ++k) {
        const Object& o = objects[k];
        materials.push_back(fmt::format("{{\"name\": \"{}\", {}}}", o.name, o.material));
        meshes.push_back(fmt::format("{{\"name\": \"{}\", \"primitives\": [{{{}, \"material\": {}}}]}}", o.name, *o.prim, k));
        nodes.push_back(fmt::format("{{\"name\": \"{}\", \"mesh\": {}, \"translation\": [{}, {}, 0], \"scale\": [{}, {}, {}]}}",
                                    o.name, k, float(o.x), float(o.y), float(o.scale), float(o.scale), float(o.scale)));
    }
    // The camera: from (0, 2.2, 7.6) towards (0, 0.4, 0), a pitch about +X.
    const double cam_y = 2.2, cam_z = 7.6, target_y = 0.4;
    const double pitch = -std::atan2(cam_y - target_y, cam_z);
    nodes.push_back(fmt::format("{{\"name\": \"camera\", \"camera\": 0, \"translation\": [0, {}, {}], "
                                "\"rotation\": [{}, 0, 0, {}]}}",
                                float(cam_y), float(cam_z), float(std::sin(0.5 * pitch)), float(std::cos(0.5 * pitch))));

    const std::string json = scene_json("whitted bench env (benchmarks/occlusion_scene.cpp)",
                                        " \"extensionsUsed\": [\"KHR_materials_transmission\", \"KHR_materials_ior\"],\n",
                                        nodes, meshes, materials, 0.62, l);
    write_glb(path, json, l.bin, "occlusion scene");
    return 4 * sphere.indices.size() / 3 + floor.indices.size() / 3 + monkey.indices.size() / 3;
}

}  // namespace whitted::app
