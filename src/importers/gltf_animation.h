// A glTF file posed at one moment: animations (glTF 2.0 section 3.11) set the nodes' translation,
// rotation, scale and morph weights; skins (section 3.7.3) and morph targets (section 3.7.2.2)
// deform the meshes. The importer places instances, cameras and lights with the posed transforms
// and builds each deformed mesh from its node's pose (docs/gltf-support.md "Animation").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "core/vecmath.h"
#include "importers/warning_log.h"
#include "scene/scene.h"

namespace whitted {

/// Every node of a file at one time: what the traversal and the mesh deformation read.
struct GltfPose {
    std::vector<Mat4d> world;                 ///< per node: its global transform (every root of the file)
    std::vector<std::vector<float>> weights;  ///< per node: morph weights of its mesh (empty: no targets)
    std::vector<uint8_t> moving;              ///< per node: a chosen animation changes its global transform
                                              ///< (a channel on its translation, rotation or scale, or an ancestor's)
    std::vector<uint8_t> morphing;            ///< per node: a chosen animation changes its morph weights
    /// KHR_animation_pointer values of properties outside the nodes: which object, which property
    /// below it ("perspective/yfov", "color", "pbrMetallicRoughness/baseColorFactor", ...), the value.
    enum class Collection { Cameras, Lights, Materials };
    struct PointerValue {
        Collection collection = Collection::Materials;
        int index = -1;
        std::string property;
        std::vector<float> value;
    };
    std::vector<PointerValue> values;
};

/// Writes the pose's animated camera, light and material properties into `model` before the
/// importer reads them (material factors already clamped to their glTF range: a spline may
/// overshoot its keys).
void apply_pointer_values(const GltfPose& pose, tinygltf::Model& model);

/// The animations `choice` names: "all" (every one), a name, or indices "0,2". Throws
/// whitted::Error naming the file and listing the animations it has when one does not exist.
std::vector<int> choose_animations(const tinygltf::Model& model, const std::string& path, const std::string& choice);

/// The nodes at `time` seconds under `animations` (each looping over its duration when `loop`),
/// with morph weights from the animation, else node.weights, else mesh.weights, else 0. Validates
/// what it reads and throws whitted::Error naming the file, the animation or node and the problem
/// (key times, value counts, targets, weights counts). KHR_animation_pointer channels apply to node
/// translation, rotation, scale and weights, camera yfov, light color and intensity, the core
/// material factors and the KHR_texture_transform offset, rotation and scale of the core texture
/// slots (written into the model by apply_pointer_values); others are skipped with one warning each.
GltfPose pose_nodes(const tinygltf::Model& model, const std::string& path, const std::vector<int>& animations,
                    double time, bool loop, WarningLog& warnings);

/// True when node `node`'s primitive needs a mesh of its own: it has a skin, or morph targets.
bool deformed(const tinygltf::Model& model, int node, int primitive);

/// True when that deformation changes over time under `pose`'s animations: its morph weights are
/// animated, or one of its skin's joints moves.
bool deforming(const tinygltf::Model& model, int node, const GltfPose& pose);

/// A skinned primitive's joints and weights per vertex (every JOINTS_n/WEIGHTS_n set, 4 influences
/// a set), read and checked once: a sequence poses the mesh from it every frame.
struct SkinBinding {
    bool skinned = false;          ///< the node has a skin and the primitive JOINTS_0 and WEIGHTS_0
    size_t influences = 0;         ///< per vertex
    std::vector<uint32_t> joints;  ///< vertex-major, `influences` per vertex (0 where the weight is 0)
    std::vector<float> weights;
};

/// The binding of node `node`'s `primitive` with `vertices` vertices (not skinned: empty). Throws
/// whitted::Error naming the JOINTS accessor for a joint index outside the skin.
SkinBinding skin_binding(const tinygltf::Model& model, const std::string& path, int node, int primitive,
                         size_t vertices);

/// Deforms `mesh`, built from `primitive` of node `node`'s mesh, to the pose: morph targets first
/// (POSITION, NORMAL, TANGENT displacements times the node's weights), then the skin (each vertex by
/// its weighted joint matrices global(joint) x inverseBindMatrix, normals by their inverse
/// transpose, tangents by the 3x3), in world space for a skinned mesh; the vertices in parallel.
/// `binding`: skin_binding() of the primitive, read here when null. Throws whitted::Error for joint
/// indices outside the skin.
void deform_mesh(Mesh& mesh, const tinygltf::Model& model, const std::string& path, int node, int primitive,
                 const GltfPose& pose, const SkinBinding* binding = nullptr);

/// The file's animations, skins and morphed meshes as Scene records (`posed`: the chosen ones).
void describe_animation(const tinygltf::Model& model, const std::vector<int>& posed, Scene& scene);

}  // namespace whitted
