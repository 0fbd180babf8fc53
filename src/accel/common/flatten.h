// Which meshes every backend may flatten into world space (docs/accelerators.md "Instances").
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace whitted {

/// Per mesh: the index of the one instance that places it when the mesh may be flattened (used
/// by that instance alone, with triangles, under a transform that keeps orientation: a mirroring
/// one would flip the winding the geometric normal follows); -1 for every other mesh. Animated
/// geometry (a deforming mesh, a moving instance) stays apart, so a frame's update refits or moves
/// it alone and the static geometry is not touched (scene_update.h).
inline std::vector<int64_t> flattenable_meshes(const Scene& scene) {
    std::vector<uint32_t> uses(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances)
        if (inst.mesh < uses.size()) ++uses[inst.mesh];
    std::vector<int64_t> placed_by(scene.meshes.size(), -1);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh < uses.size() && uses[inst.mesh] == 1 && scene.meshes[inst.mesh].triangle_count() > 0 &&
            inst.world_from_object.det3() > 0.0 && !inst.moving && !scene.meshes[inst.mesh].deforming)
            placed_by[inst.mesh] = int64_t(i);
    }
    return placed_by;
}

}  // namespace whitted
