// In-house backends built on the binary BVH of bvh_tree.h: `bvh` (box or sphere nodes, float or
// double precision), `kdop` (Kay-Kajiya 7-slab nodes) and `brute` (no structure: the oracle).
#pragma once

#include <memory>

#include "accel/accelerator.h"
#include "accel/bvh/bvh_tree.h"

namespace whitted {

/// Scalar type the in-house traversal computes in.
enum class Precision : uint8_t {
    Float,   ///< as fast as it gets; the path that is compared with Embree
    Double,  ///< reference: vertices, transforms, ray and triangle test in double
};

/// Bounding volume of BVH nodes.
enum class BoundingVolume : uint8_t {
    Aabb,    ///< axis-aligned box, conservative slab test (Ize 2013)
    Sphere,  ///< bounding sphere around the box centre holding all the subtree's vertices
};

/// Settings of the `bvh` backend.
struct BvhConfig {
    BvhBuildConfig build;                        ///< binned SAH settings (bvh_tree.h)
    BoundingVolume volume = BoundingVolume::Aabb;///< node test (`--bv aabb|sphere`)
    Precision precision = Precision::Float;      ///< `--precision float|double`
    int width = 0;                               ///< children per node: 8 or 4 (wide_bvh.h, float boxes
                                                 ///< only), 2 (the binary tree; always for double/sphere),
                                                 ///< 0 = 8 where the CPU has AVX2, else 4
    bool allow_avx2 = true;                      ///< `isa=sse2` false: 8-wide node tests in SSE halves
    bool flatten = true;                         ///< meshes used by one instance share one world-space
                                                 ///< BLAS (common/two_level.h; float only); `flatten=0`:
                                                 ///< every mesh in its own
};

/// The binned SAH settings `bvh` uses for wide trees (width 4 or 8) unless options override them.
inline BvhBuildConfig wide_bvh_build_defaults() {
    BvhBuildConfig b;
    b.leaf_block = 4;           // leaves are tested in packets of four triangles (wide_bvh.h)
    b.intersection_cost = 2.f;  // a packet test costs about two binary node steps
    return b;
}

/// Settings of the `kdop` backend: the same SAH topology, nodes bounded by 7-slab k-DOPs fitted
/// to the triangles below them.
struct KdopConfig {
    BvhBuildConfig build;                        ///< binned SAH settings for the topology
};

/// Settings of the `brute` oracle.
struct BruteForceConfig {
    Precision precision = Precision::Float;      ///< double = ground truth for float error
};

/// Two-level SAH BVH (BLAS per mesh, TLAS over instances, one more BVH over the spheres),
/// watertight triangle test, stable sphere test (common/sphere.h). With float boxes and width 4
/// or 8 the mesh BVHs and the top level are wide (SIMD node tests, triangles four at a time:
/// wide_bvh.h); the sphere BVH stays binary.
std::unique_ptr<Accelerator> create_bvh_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                    const BvhConfig& config);
/// Two-level BVH whose nodes are k-DOPs (Kay & Kajiya 1986), spheres likewise.
std::unique_ptr<Accelerator> create_kdop_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                     const KdopConfig& config);
/// Tests every triangle of every instance and every sphere: O(n) per ray, the oracle the others
/// are checked against.
std::unique_ptr<Accelerator> create_brute_force_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                            const BruteForceConfig& config);

}  // namespace whitted
