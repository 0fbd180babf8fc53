// A binary glTF written by hand, for the generated benchmark scenes (generated_skin.cpp,
// material_samples.cpp): a buffer built view by view, the JSON around it, and the GLB container.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace whitted::app {

/// The binary buffer, built view by view (each 4-byte aligned), and the JSON of its views and accessors.
struct GlbLayout {
    std::vector<uint8_t> bin;
    std::vector<std::string> views, accessors;

    /// Appends `data` as a view (with `target` when non-zero) and one accessor of `count` elements
    /// over it; returns the accessor index.
    template <typename T>
    int add(const std::vector<T>& data, int component, const char* type, size_t count, int target,
            const std::string& extra = "") {
        const size_t offset = bin.size();
        const size_t length = data.size() * sizeof(T);
        bin.resize(offset + length);
        std::memcpy(bin.data() + offset, data.data(), length);
        bin.resize((bin.size() + 3) & ~size_t(3), 0);
        views.push_back(fmt::format("{{\"buffer\": 0, \"byteOffset\": {}, \"byteLength\": {}{}}}", offset, length,
                                    target ? fmt::format(", \"target\": {}", target) : ""));
        accessors.push_back(fmt::format("{{\"bufferView\": {}, \"componentType\": {}, \"count\": {}, \"type\": \"{}\"{}}}",
                                        views.size() - 1, component, count, type, extra));
        return int(accessors.size() - 1);
    }
};

/// Vertex attributes and triangles of one mesh.
struct MeshData {
    std::vector<float> positions, normals, uvs, tangents;
    std::vector<uint32_t> indices;

    size_t vertices() const { return positions.size() / 3; }
    void vertex(double px, double py, double pz, double nx, double ny, double nz, double u, double v, double tx,
                double ty, double tz, double w) {
        positions.insert(positions.end(), {float(px), float(py), float(pz)});
        normals.insert(normals.end(), {float(nx), float(ny), float(nz)});
        uvs.insert(uvs.end(), {float(u), float(v)});
        tangents.insert(tangents.end(), {float(tx), float(ty), float(tz), float(w)});
    }
};

/// A UV sphere of `radius` about the origin: vertex (i, j) at longitude 2 pi i / segments and
/// colatitude pi j / rings, with a seam column (u = 1) and pole rows; u runs with the longitude, v
/// from the top pole down. The tangent is dP/du (about +Y), the bitangent cross(N, T) = dP/dv
/// (w = +1). Triangles are counter-clockwise seen from outside; the degenerate ones at the poles are
/// left out.
MeshData uv_sphere(double radius, int segments, int rings);

/// A floor: one quad at y = 0 facing +Y over x in [-half_x, half_x], z in [z_back, z_front]; u along
/// +x, v along +z (so w = -1: cross(N, T) = -z).
MeshData floor_quad(double half_x, double z_back, double z_front);

/// Adds a mesh's accessors (POSITION with its bounds, NORMAL, and TEXCOORD_0 and TANGENT when the mesh
/// has them); returns the primitive's "attributes" and "indices" JSON (no material).
std::string add_mesh(GlbLayout& l, const MeshData& m);

/// The unit quaternion (x, y, z, w) turning -Z (where glTF cameras look and lights shine) to unit d,
/// as JSON; d must not be +Z.
std::string rotation_to(double dx, double dy, double dz);

/// A pbrMetallicRoughness block (JSON member).
std::string pbr(double r, double g, double b, double metallic, double roughness);

/// The glTF JSON of a generated scene: the asset's `generator`, `members` (whole top-level members,
/// each ending in ",\n": extensionsUsed, extensions), one scene of every node, one perspective
/// camera (aspect 4:3, vertical field of view `yfov` radians), the meshes, materials and l's
/// accessors, views and buffer.
std::string scene_json(const std::string& generator, const std::string& members, const std::vector<std::string>& nodes,
                       const std::vector<std::string>& meshes, const std::vector<std::string>& materials, double yfov,
                       const GlbLayout& l);

/// The items joined by `separator`.
std::string join(const std::vector<std::string>& items, const char* separator);

/// Writes `json` and `bin` as a GLB (glTF 2.0 section 4.4: the JSON chunk padded with spaces, the
/// BIN chunk with zeros) and returns its size; throws whitted::Error naming `what` when it does not
/// fit a GLB or cannot be written.
size_t write_glb(const std::filesystem::path& path, const std::string& json, const std::vector<uint8_t>& bin,
                 const char* what);

}  // namespace whitted::app
