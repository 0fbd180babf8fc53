// The GLB container of the generated benchmark scenes (glb_writer.h).
#include "benchmarks/glb_writer.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

#include "core/error.h"

namespace whitted::app {

namespace {

void put_u32(std::string& s, uint32_t v) {
    for (int b = 0; b < 4; ++b) s.push_back(char((v >> (8 * b)) & 0xFF));
}

}  // namespace

MeshData uv_sphere(double radius, int segments, int rings) {
    MeshData m;
    for (int j = 0; j <= rings; ++j) {
        const double theta = std::numbers::pi * j / rings;
        for (int i = 0; i <= segments; ++i) {
            const double phi = 2.0 * std::numbers::pi * i / segments;
            const double nx = std::sin(theta) * std::cos(phi), ny = std::cos(theta), nz = std::sin(theta) * std::sin(phi);
            m.vertex(radius * nx, radius * ny, radius * nz, nx, ny, nz, double(i) / segments, double(j) / rings,
                     -std::sin(phi), 0.0, std::cos(phi), 1.0);
        }
    }
    const uint32_t row = uint32_t(segments) + 1;
    for (uint32_t j = 0; j < uint32_t(rings); ++j)
        for (uint32_t i = 0; i < uint32_t(segments); ++i) {
            const uint32_t a = j * row + i, b = a + 1, c = a + row, d = c + 1;
            if (j > 0) m.indices.insert(m.indices.end(), {a, b, c});                    // not at the top pole
            if (j + 1 < uint32_t(rings)) m.indices.insert(m.indices.end(), {b, d, c});  // not at the bottom pole
        }
    return m;
}

MeshData floor_quad(double half_x, double z_back, double z_front) {
    MeshData m;
    const double w = 2.0 * half_x, d = z_front - z_back;
    const double corners[4][2] = {{-half_x, z_back}, {-half_x, z_front}, {half_x, z_front}, {half_x, z_back}};
    for (const auto& [x, z] : corners)
        m.vertex(x, 0.0, z, 0.0, 1.0, 0.0, (x + half_x) / w, (z - z_back) / d, 1.0, 0.0, 0.0, -1.0);
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

std::string add_mesh(GlbLayout& l, const MeshData& m) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t v = 0; v < m.vertices(); ++v)
        for (size_t c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], m.positions[3 * v + c]);
            hi[c] = std::max(hi[c], m.positions[3 * v + c]);
        }
    const std::string bounds =
        fmt::format(", \"min\": [{}, {}, {}], \"max\": [{}, {}, {}]", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    const int pos = l.add(m.positions, 5126, "VEC3", m.vertices(), 34962, bounds);
    const int nrm = l.add(m.normals, 5126, "VEC3", m.vertices(), 34962);
    std::string attributes = fmt::format("\"POSITION\": {}, \"NORMAL\": {}", pos, nrm);
    if (!m.uvs.empty()) attributes += fmt::format(", \"TEXCOORD_0\": {}", l.add(m.uvs, 5126, "VEC2", m.vertices(), 34962));
    if (!m.tangents.empty())
        attributes += fmt::format(", \"TANGENT\": {}", l.add(m.tangents, 5126, "VEC4", m.vertices(), 34962));
    const int idx = l.add(m.indices, 5125, "SCALAR", m.indices.size(), 34963);
    return fmt::format("\"attributes\": {{{}}}, \"indices\": {}", attributes, idx);
}

std::string rotation_to(double dx, double dy, double dz) {
    // q = (cross(a, d), 1 + dot(a, d)) normalised, a = (0, 0, -1).
    const double x = dy, y = -dx, z = 0.0, w = 1.0 - dz;
    const double n = std::sqrt(x * x + y * y + z * z + w * w);
    return fmt::format("[{}, {}, {}, {}]", float(x / n), float(y / n), float(z / n), float(w / n));
}

std::string pbr(double r, double g, double b, double metallic, double roughness) {
    return fmt::format("\"pbrMetallicRoughness\": {{\"baseColorFactor\": [{}, {}, {}, 1], \"metallicFactor\": {}, "
                       "\"roughnessFactor\": {}}}",
                       float(r), float(g), float(b), float(metallic), float(roughness));
}

std::string scene_json(const std::string& generator, const std::string& members, const std::vector<std::string>& nodes,
                       const std::vector<std::string>& meshes, const std::vector<std::string>& materials, double yfov,
                       const GlbLayout& l) {
    std::vector<std::string> roots;
    for (size_t i = 0; i < nodes.size(); ++i) roots.push_back(std::to_string(i));
    return fmt::format(
        "{{\"asset\": {{\"version\": \"2.0\", \"generator\": \"{}\"}},\n"
        "{}"
        " \"scene\": 0, \"scenes\": [{{\"nodes\": [{}]}}],\n"
        " \"nodes\": [\n  {}],\n"
        " \"cameras\": [{{\"type\": \"perspective\", \"perspective\": {{\"yfov\": {}, \"aspectRatio\": 1.3333334, "
        "\"znear\": 0.05}}}}],\n"
        " \"meshes\": [\n  {}],\n"
        " \"materials\": [\n  {}],\n"
        " \"accessors\": [\n  {}],\n"
        " \"bufferViews\": [\n  {}],\n"
        " \"buffers\": [{{\"byteLength\": {}}}]}}\n",
        generator, members, join(roots, ", "), join(nodes, ",\n  "), float(yfov), join(meshes, ",\n  "),
        join(materials, ",\n  "), join(l.accessors, ",\n  "), join(l.views, ",\n  "), l.bin.size());
}

std::string join(const std::vector<std::string>& items, const char* separator) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
    return out;
}

size_t write_glb(const std::filesystem::path& path, const std::string& json, const std::vector<uint8_t>& bin,
                 const char* what) {
    std::string json_chunk = json;
    json_chunk.resize((json_chunk.size() + 3) & ~size_t(3), ' ');
    const size_t total = 12 + 8 + json_chunk.size() + 8 + bin.size();
    if (total > 0xFFFFFFFFu) throw Error(fmt::format("{}: {} bytes do not fit a GLB", what, total));
    std::string head = "glTF";
    put_u32(head, 2);
    put_u32(head, uint32_t(total));
    put_u32(head, uint32_t(json_chunk.size()));
    head += "JSON";
    std::string bin_head;
    put_u32(bin_head, uint32_t(bin.size()));
    bin_head += std::string("BIN\0", 4);
    std::ofstream f(path, std::ios::binary);
    f.write(head.data(), std::streamsize(head.size()));
    f.write(json_chunk.data(), std::streamsize(json_chunk.size()));
    f.write(bin_head.data(), std::streamsize(bin_head.size()));
    f.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
    if (!f) throw Error(fmt::format("{}: cannot write {}", what, path.string()));
    return total;
}

}  // namespace whitted::app
