// Binary BVH topology: a binned SAH builder (parallel over TBB, deterministic) and an ordered
// stack traversal, generic over the node's bounding volume (box, sphere, k-DOP) and over what a
// leaf holds (triangles in a BLAS, instances in the TLAS). Models: bvh v2 (Meister), tinybvh
// (Bikker), pbrt-v4 BVHAggregate; binned SAH after Wald 2007.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "accel/common/geometry.h"
#include "core/vecmath.h"

namespace whitted {

/// Settings of the binned SAH build.
struct BvhBuildConfig {
    int bins = 16;                    ///< centroid bins per axis and node (8..64 sensible)
    int max_leaf_size = 8;            ///< a node with more primitives is always split
    float traversal_cost = 1.f;       ///< SAH cost of visiting a node, relative to ...
    float intersection_cost = 1.f;    ///< ... the cost of testing one primitive
    size_t parallel_threshold = 4096; ///< nodes with at least this many primitives build their children in parallel
    int leaf_block = 1;               ///< the SAH counts a leaf's primitives in blocks of this many, rounded up
                                      ///< (4 for the wide BVH, whose leaves test triangles four at a time)
};

/// Primitives counted in blocks of `block` (the intersection tests a leaf of n primitives costs).
inline uint32_t sah_blocks(uint32_t n, int block) {
    return block <= 1 ? n : (n + uint32_t(block) - 1) / uint32_t(block);
}

/// A node as the builder leaves it: box, children or primitive range. Inner nodes have
/// count == 0 and their children at index, index + 1; leaves hold ids[index, index + count).
/// [begin, end) is the primitive range of the whole subtree (for fitting other volumes).
template <typename T>
struct BuildNode {
    Bounds3<T> box;
    uint32_t index = 0, count = 0;
    uint32_t begin = 0, end = 0;
};

/// Half the surface area of a box (the SAH only needs ratios).
template <typename T>
inline T half_area(const Bounds3<T>& b) {
    if (b.empty()) return T(0);
    const Vec3<T> d = b.diagonal();
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

/// Builds a BVH over primitives with the given boxes. On return `ids` maps leaf slots to
/// primitive indices; the node array is depth-first with sibling pairs adjacent, root at 0
/// (empty when there are no primitives). The result depends only on the input, never on the
/// number of threads.
template <typename T>
std::vector<BuildNode<T>> build_bvh(const std::vector<Bounds3<T>>& boxes, const BvhBuildConfig& config,
                                    std::vector<uint32_t>& ids);

/// SAH cost of a finished tree (sum over nodes of area ratio x cost), as tinybvh reports it.
template <typename T>
double sah_cost(const std::vector<BuildNode<T>>& nodes, const BvhBuildConfig& config);

/// The traversal stack depth; the builder caps the tree depth below it.
constexpr int kBvhMaxDepth = 64;

/// A node of a finished tree with bounding volume V (32 bytes for a float box).
template <typename V>
struct BvhNode {
    V volume;
    uint32_t index = 0;               ///< first child (inner) or first primitive slot (leaf)
    uint32_t count = 0;               ///< 0 for inner nodes, else primitives in the leaf
};

/// Ordered depth-first traversal: the nearer child is visited first, the farther one is pushed
/// with its entry distance and skipped when popped beyond the current `tmax` (which the leaf
/// callback may shrink). `leaf(first, count)` returns true to end the traversal.
template <typename T, typename V, typename RayData, typename Leaf>
inline void traverse_bvh(const std::vector<BvhNode<V>>& nodes, const RayData& ray, T tmin, const T& tmax, Leaf&& leaf) {
    constexpr T kMiss = std::numeric_limits<T>::infinity();
    if (nodes.empty() || volume_entry(ray, nodes[0].volume, tmin, tmax) == kMiss) return;
    struct Entry {
        uint32_t node;
        T dist;
    };
    Entry stack[kBvhMaxDepth + 2];
    int sp = 0;
    uint32_t current = 0;
    for (;;) {
        const BvhNode<V>& n = nodes[current];
        if (n.count == 0) {
            uint32_t c0 = n.index, c1 = n.index + 1;
            T d0 = volume_entry(ray, nodes[c0].volume, tmin, tmax);
            T d1 = volume_entry(ray, nodes[c1].volume, tmin, tmax);
            if (d1 < d0) {
                std::swap(d0, d1);
                std::swap(c0, c1);
            }
            if (d0 != kMiss) {
                if (d1 != kMiss) stack[sp++] = {c1, d1};
                current = c0;
                continue;
            }
        } else if (leaf(n.index, n.count)) {
            return;
        }
        // Pop the next node still in front of the current closest hit.
        for (;;) {
            if (sp == 0) return;
            const Entry e = stack[--sp];
            if (e.dist <= tmax * kRayTmaxScale<T> + ray.t_slack) {
                current = e.node;
                break;
            }
        }
    }
}

}  // namespace whitted
