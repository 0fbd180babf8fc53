#include "scene/scene.h"

#include <algorithm>

namespace whitted {

void Scene::warn(const std::string& message) {
    if (std::find(warnings.begin(), warnings.end(), message) == warnings.end()) warnings.push_back(message);
}

Bounds3d Scene::world_bounds() const {
    // Object-space bounds per mesh once, then the 8 transformed corners per instance.
    std::vector<Bounds3d> mesh_bounds(meshes.size());
    for (size_t i = 0; i < meshes.size(); ++i) mesh_bounds[i] = meshes[i].bounds();
    Bounds3d b;
    for (const Instance& inst : instances) {
        const Bounds3d& mb = mesh_bounds[inst.mesh];
        if (!mb.empty()) b.extend(transform_bounds(inst.world_from_object, mb));
    }
    for (const Sphere& s : spheres) {
        b.extend(s.center - Vec3d(s.radius));
        b.extend(s.center + Vec3d(s.radius));
    }
    return b;
}

size_t Scene::instanced_triangle_count() const {
    size_t n = 0;
    for (const Instance& inst : instances) n += meshes[inst.mesh].triangle_count();
    return n;
}

size_t Scene::mesh_triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangle_count();
    return n;
}

}  // namespace whitted
