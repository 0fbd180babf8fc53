// SceneUpdate: what changed when a Scene was posed again in place (the next frame of an
// animation), for the stages that precompute from it: the scene view and the accelerator refit
// or move what is named here and leave everything else as it was.
//
// What an update may change: the vertex positions, normals and tangents of meshes marked
// `deforming` (same counts, same indices, the positions in their own allocation, which the Embree
// backend shares), the transforms of instances marked `moving`, and the cameras, lights and
// material factors. Anything else (counts, indices, which mesh an instance uses, textures) needs
// a new Scene.
#pragma once

#include <cstdint>
#include <vector>

namespace whitted {

struct SceneUpdate {
    std::vector<uint32_t> meshes;     ///< meshes whose vertices were rewritten, ascending
    std::vector<uint32_t> instances;  ///< instances whose world_from_object changed, ascending
    bool cameras = false;             ///< Scene::cameras rewritten (same count)
    bool lights = false;              ///< Scene::lights rewritten (same count)
    bool materials = false;           ///< material factors rewritten (same count, same textures)
    bool reloaded = false;            ///< the Scene was replaced as a whole (loaded again): everything
                                      ///< built from it must be built anew; the fields above are unset

    /// True when the geometry moved: the accelerator must be brought up to date.
    bool geometry() const { return !meshes.empty() || !instances.empty(); }
    bool empty() const { return !geometry() && !cameras && !lights && !materials && !reloaded; }
};

}  // namespace whitted
