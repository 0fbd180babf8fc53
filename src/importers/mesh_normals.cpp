#include "importers/mesh_normals.h"

namespace whitted {

std::vector<Vec3f> smooth_normals(const Mesh& mesh) {
    std::vector<Vec3f> acc(mesh.positions.size(), Vec3f(0.f));
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        const Vec3f fn = cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
        acc[a] += fn, acc[b] += fn, acc[c] += fn;
    }
    for (Vec3f& n : acc) {
        n = normalize(n);
        if (!(length(n) > 0.5f)) n = {0.f, 0.f, 1.f};
    }
    return acc;
}

}  // namespace whitted
