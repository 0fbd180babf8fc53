// `octree`: an adaptive octree per mesh (and one over the scene's spheres; Glassner 1984),
// traversed front to back.
#pragma once

#include <cstdint>
#include <memory>

#include "accel/accelerator.h"

namespace whitted {

/// Settings of the `octree` backend. A node is subdivided while it holds more than
/// `max_leaf_size` triangles, unless one of the limits below stops it.
struct OctreeConfig {
    uint32_t max_leaf_size = 1;      ///< subdivide every node holding more than one triangle
    int max_depth = 12;              ///< depth limit (the root is depth 0); hard cap 20
    float min_extent = 1e-5f;        ///< no node smaller than this fraction of the root's extent
    int max_stalled_levels = 0;      ///< subdivisions allowed in a row where a child keeps every
                                     ///< triangle of its parent: triangles sharing a vertex or an
                                     ///< edge can never be separated, and refining along them up to
                                     ///< max_depth costs millions of nodes (0 = make it a leaf)
};

/// Two-level octree: an octree per mesh, a SAH BVH over the instances, and one world-space octree
/// over the spheres.
std::unique_ptr<Accelerator> create_octree_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                       const OctreeConfig& config);

}  // namespace whitted
