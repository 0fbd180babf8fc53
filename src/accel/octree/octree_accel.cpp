#include "accel/octree/octree_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <memory>

#include "accel/common/mailbox.h"
#include "accel/bvh/two_level.h"

namespace whitted {

namespace {

constexpr int kOctreeHardMaxDepth = 20;
constexpr uint32_t kInner = ~0u;

/// Child c of a cube: bit 0 = upper half in x, bit 1 in y, bit 2 in z. Build and traversal
/// compute child boxes with this same arithmetic, so they agree to the bit.
inline void child_box(const Vec3f& lo, const Vec3f& hi, int c, Vec3f& clo, Vec3f& chi) {
    const Vec3f mid = (lo + hi) * 0.5f;
    for (int a = 0; a < 3; ++a) {
        const bool upper = (c >> a) & 1;
        clo[a] = upper ? mid[a] : lo[a];
        chi[a] = upper ? hi[a] : mid[a];
    }
}

/// An adaptive octree over a primitive set P (one mesh's triangles, or the scene's spheres); a
/// primitive goes to every child its overlap test accepts (for spheres: the children the surface
/// passes through).
template <typename P>
class PrimOctree {
public:
    PrimOctree(P prims, const OctreeConfig& config) : m_prims(std::move(prims)), m_config(config) {
        for (uint32_t i = 0; i < m_prims.size(); ++i) m_bounds.extend(m_prims.bounds(i));
        // A cube around the primitives, padded so that vertices on its faces are inside.
        const Vec3f c = m_bounds.center();
        // Half size of the root cube, padded relative to the coordinates too (see the grid).
        const float mag = abs_extent(m_bounds.lo, m_bounds.hi);
        const float half = max_component(m_bounds.diagonal()) * 0.5f * (1.f + 1e-5f) + mag * 1e-6f + 1e-30f;
        m_root_lo = c - Vec3f(half);
        m_root_hi = c + Vec3f(half);
        m_min_extent = 2.f * half * config.min_extent;
        m_max_depth = std::clamp(config.max_depth, 0, kOctreeHardMaxDepth);

        std::vector<uint32_t> all(m_prims.size());
        for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
        std::unique_ptr<TempNode> root = build(std::move(all), m_root_lo, m_root_hi, 0, 0);
        flatten(*root);
    }

    template <class Query>
    bool traverse(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        const SlabRay<float> slab(org, dir, abs_extent(m_root_lo, m_root_hi));
        const typename P::RayData pr = P::ray_data(org, dir);
        // Children are visited in the order i ^ mask, i = 0..7: a ray crosses each midplane at
        // most once, in the direction of its sign, so this is front to back for any ray.
        const int mask = (std::signbit(dir.x) ? 1 : 0) | (std::signbit(dir.y) ? 2 : 0) | (std::signbit(dir.z) ? 4 : 0);
        struct Entry {
            uint32_t node;
            Vec3f lo, hi;
        };
        Entry stack[8 * kOctreeHardMaxDepth + 8];
        int sp = 0;
        stack[sp++] = {0, m_root_lo, m_root_hi};
        Mailbox mailbox;
        while (sp > 0) {
            const Entry e = stack[--sp];
            // Skip nodes the ray misses or that lie beyond the current closest hit.
            if (slab_entry(slab, e.lo, e.hi, tnear, q.tmax) == kInfinity) continue;
            const Node& n = m_nodes[e.node];
            if (n.count != kInner) {
                if (test_mailboxed_refs(m_refs, n.index, n.index + n.count, m_prims, mailbox, pr, tnear, q)) return true;
                continue;
            }
            for (int i = 7; i >= 0; --i) {
                const int c = i ^ mask;
                Entry& ce = stack[sp++];
                ce.node = n.index + uint32_t(c);
                child_box(e.lo, e.hi, c, ce.lo, ce.hi);
            }
        }
        return false;
    }

    Bounds3f bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_nodes.size() * sizeof(Node) + m_refs.size() * 4 + m_prims.bytes(), m_nodes.size(), m_refs.size(), 0.0};
    }

private:
    struct Node {
        uint32_t index;   ///< first of 8 children (inner) or first reference (leaf)
        uint32_t count;   ///< kInner or the leaf's reference count
    };
    struct TempNode {
        std::vector<uint32_t> prims;
        std::array<std::unique_ptr<TempNode>, 8> children;
        bool leaf() const { return !children[0]; }
    };

    std::unique_ptr<TempNode> build(std::vector<uint32_t> prims, const Vec3f& lo, const Vec3f& hi, int depth,
                                    int stalled) const {
        auto node = std::make_unique<TempNode>();
        if (prims.size() <= m_config.max_leaf_size || depth >= m_max_depth || (hi.x - lo.x) * 0.5f < m_min_extent) {
            node->prims = std::move(prims);
            return node;
        }
        // Distribute the primitives over the 8 children (a primitive may go to several).
        std::array<std::vector<uint32_t>, 8> sub;
        std::array<Vec3f, 8> clo, chi;
        for (int c = 0; c < 8; ++c) child_box(lo, hi, c, clo[size_t(c)], chi[size_t(c)]);
        for (uint32_t p : prims)
            for (int c = 0; c < 8; ++c)
                if (m_prims.overlaps_box(p, clo[size_t(c)], chi[size_t(c)])) sub[size_t(c)].push_back(p);
        bool stalls = false;
        for (const auto& s : sub) stalls |= s.size() == prims.size();
        const int next_stalled = stalls ? stalled + 1 : 0;
        if (next_stalled > m_config.max_stalled_levels) {  // no progress: keep them together
            node->prims = std::move(prims);
            return node;
        }
        auto build_child = [&](size_t c) {
            node->children[c] = build(std::move(sub[c]), clo[c], chi[c], depth + 1, next_stalled);
        };
        if (prims.size() >= 4096) tbb::parallel_for(size_t(0), size_t(8), build_child);
        else
            for (size_t c = 0; c < 8; ++c) build_child(c);
        return node;
    }

    /// Breadth-first into the flat array: the 8 children of a node are consecutive.
    void flatten(const TempNode& root) {
        std::vector<const TempNode*> order{&root};
        m_nodes.push_back({0, 0});
        for (size_t i = 0; i < order.size(); ++i) {
            const TempNode& t = *order[i];
            if (t.leaf()) {
                m_nodes[i] = {uint32_t(m_refs.size()), uint32_t(t.prims.size())};
                m_refs.insert(m_refs.end(), t.prims.begin(), t.prims.end());
                continue;
            }
            m_nodes[i] = {uint32_t(m_nodes.size()), kInner};
            for (const auto& c : t.children) {
                order.push_back(c.get());
                m_nodes.push_back({0, 0});
            }
        }
    }

    P m_prims;
    OctreeConfig m_config;
    Bounds3f m_bounds;
    Vec3f m_root_lo, m_root_hi;
    float m_min_extent = 0.f;
    int m_max_depth = 12;
    std::vector<Node> m_nodes;
    std::vector<uint32_t> m_refs;
};

}  // namespace

std::unique_ptr<Accelerator> create_octree_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                       const OctreeConfig& config) {
    using Blas = PrimOctree<TrianglePrims<float>>;
    using SphereBlas = PrimOctree<AnalyticPrims<float>>;
    // The mesh builder outlives this call (update() builds a deformed mesh again): config by value.
    return std::make_unique<TwoLevelAccelerator<float, Blas, SphereBlas>>(
        "octree", scene, filter, [config](const Mesh& m) { return Blas(TrianglePrims<float>(m), config); },
        [&](AnalyticPrims<float>&& s) { return SphereBlas(std::move(s), config); }, true);
}

}  // namespace whitted
