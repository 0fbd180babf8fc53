// Box and rectangle generation for the scene file.

#include "importers/scene_file_geometry.h"

#include <cmath>
#include <utility>

namespace whitted {

namespace {

/// Appends a quad with corners center + su*hu*u + sv*hv*v (su, sv = -1/+1) as two triangles
/// facing cross(u, v) = n.
void add_quad(Mesh& mesh, const Vec3d& center, const Vec3d& u, const Vec3d& v, const Vec3d& n, double hu, double hv) {
    const auto base = uint32_t(mesh.positions.size());
    const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k) {
        mesh.positions.push_back(Vec3f(center + u * (su[k] * hu) + v * (sv[k] * hv)));
        mesh.normals.push_back(Vec3f(n));
        // u to the right, v up, image row 0 at the top (glTF UV convention).
        mesh.uv0.push_back({float(0.5 * (su[k] + 1)), float(1 - 0.5 * (sv[k] + 1))});
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

}  // namespace

Mesh make_box_mesh(const Vec3d& lo, const Vec3d& hi) {
    Mesh mesh;
    const Vec3d c = (lo + hi) * 0.5, h = (hi - lo) * 0.5;
    // (normal, u, v) with cross(u, v) = normal: right and up seen from outside the face.
    struct Face {
        Vec3d n, u, v;
    };
    const Face faces[6] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    auto extent = [&](const Vec3d& axis) { return std::fabs(dot(axis, h)); };
    for (const Face& f : faces) add_quad(mesh, c + f.n * h, f.u, f.v, f.n, extent(f.u), extent(f.v));
    return mesh;
}

Mesh make_rectangle_mesh(const Vec3d& center, const Vec3d& normal, const Vec3d& u_axis, double width, double height) {
    Mesh mesh;
    add_quad(mesh, center, u_axis, cross(normal, u_axis), normal, 0.5 * width, 0.5 * height);
    return mesh;
}

Vec3d default_u_axis(const Vec3d& n) {
    const Vec3d axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int best = 0;
    for (int k = 1; k < 3; ++k)
        if (std::fabs(n[k]) < std::fabs(n[best])) best = k;
    return normalize(axes[best] - n * dot(n, axes[best]));
}

void flip_winding(Mesh& mesh) {
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    for (Vec4f& t : mesh.tangents) t.w = -t.w;
}

}  // namespace whitted
