// Wide BVH over one mesh's triangles (float): the binary SAH tree of bvh_tree.h collapsed into
// nodes of N = 4 or 8 children whose boxes are tested together with SIMD, and leaves of triangles
// stored and tested four at a time (structure of arrays). The same WideTree serves `bvh`'s top
// level over instances (WideInstanceTree, at the end), which hands its per-ray constants (WideRay)
// to the identity-transform meshes. Models: Wald, Benthin & Boulos 2008 (multi-branching BVH),
// Embree's BVH4/BVH8 with Triangle4 leaves, bvh v2's collapse and tinybvh's BVH8_CPU.
//
// Results are those of the binary `bvh:width=2`: the node test is the conservative slab test of
// geometry.h (Ize 2013) on N lanes, the leaf test the watertight test (Woop, Benthin & Wald 2013)
// with every operation in the same order on four lanes, and hits are reported in the scalar leaf
// loop's order. Only the order in which leaves are visited differs, which can change which of two
// hits at exactly the same t wins. 8-wide node tests run in AVX2 where the CPU has it (runtime
// dispatch, simd.h), else as two SSE halves. Details: docs/accelerators.md, "Wide BVH".
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "accel/bvh/bvh_tree.h"
#include "accel/common/geometry.h"
#include "accel/common/primitives.h"
#include "accel/common/simd.h"
#include "accel/bvh/two_level.h"
#include "core/error.h"

namespace whitted {

/// Four triangles of one leaf (160 bytes): v[vertex][axis] holds that coordinate of the four
/// triangles, id their original indices (-1 on padding lanes, which repeat the leaf's last
/// triangle).
struct alignas(16) TrianglePacket4 {
    simd::vfloat<4> v[3][3];
    simd::vint<4> id;
};

/// A node of the N-wide tree: the children's boxes as structure of arrays (bounds[2 k] = lower,
/// bounds[2 k + 1] = upper bound along axis k), and per child either a node index (count == 0)
/// or a leaf's first packet and packet count. Unused slots hold empty boxes and are masked by
/// `used`. 256 bytes for N = 8, 128 for N = 4.
template <int N>
struct alignas(4 * N) WideNode {
    simd::vfloat<N> bounds[6];
    uint32_t child[N];
    uint16_t count[N];
    uint32_t used = 0;   ///< bit i set when child slot i exists
};

/// Settings of the wide BVH beyond the binary build.
struct WideBvhOptions {
    bool allow_avx2 = true;   ///< 8-wide node tests in AVX2 when the CPU has it (false: SSE halves)
};

/// Per-ray constants of the N-wide node test and of the packet triangle test, computed once per
/// ray: the instance level computes them for the world-space ray and hands them to every
/// identity-transform BLAS the ray enters (a transformed instance computes its own), so a ray
/// pays the reciprocals, the shear and the broadcasts once, not once per mesh.
///   - node test: SlabRay's reciprocal direction and sign bits as N lanes; the exit scale of
///     slab_entry folded into the far plane's reciprocal (the same four roundings, difference,
///     reciprocal, two products, so the same bound, Ize 2013);
///   - triangle test: WatertightRay's permutation and shear, the origin's components permuted,
///     on four lanes.
/// Only the culling slack depends on the structure (its extent): cull_slack().
template <int N>
struct WideRay {
    using vf = simd::vfloat<N>;
    using vf4 = simd::vfloat<4>;

    Vec3f org, dir;
    float tnear;
    vf org_v[3], inv_v[3], inv_far_v[3];
    vf tnear_v;
    int near_plane[3], far_plane[3];
    int kx, ky, kz;
    vf4 ox, oy, oz, sx, sy, sz;

    WHITTED_ALWAYS_INLINE WideRay(const Vec3f& o, const Vec3f& d, float tn) : org(o), dir(d), tnear(tn) {
        const SlabRay<float> slab(o, d);
        for (int k = 0; k < 3; ++k) {
            org_v[k] = vf{} + component(slab.org, k);
            inv_v[k] = vf{} + component(slab.inv_dir, k);
            inv_far_v[k] = vf{} + component(slab.inv_dir, k) * kSlabExitScale<float>;
            near_plane[k] = 2 * k + (slab.neg[k] ? 1 : 0);
            far_plane[k] = 2 * k + (slab.neg[k] ? 0 : 1);
        }
        tnear_v = vf{} + tn;
        const WatertightRay<float> w(o, d);
        kx = w.kx;
        ky = w.ky;
        kz = w.kz;
        ox = vf4{} + component(w.org, w.kx);
        oy = vf4{} + component(w.org, w.ky);
        oz = vf4{} + component(w.org, w.kz);
        sx = vf4{} + w.sx;
        sy = vf4{} + w.sy;
        sz = vf4{} + w.sz;
    }

    /// SlabRay::t_slack of a structure whose coordinates are bounded by `extent` (0: none).
    WHITTED_ALWAYS_INLINE float cull_slack(float extent) const {
        return extent > 0.f ? SlabRay<float>::cull_slack(org, dir, extent) : 0.f;
    }
};

/// The nodes of an N-wide tree and their ordered traversal, generic over what a leaf holds
/// (packets of triangles in a mesh's BVH, instances in the top level).
template <int N>
class WideTree {
    static_assert(N == 4 || N == 8, "wide BVH nodes hold 4 or 8 children");
    using vf = simd::vfloat<N>;

public:
    /// Collapses the binary tree `built` (bvh_tree.h; not empty). `pack_leaf(first, count)` stores
    /// the items of the binary leaf holding slots [first, first + count) of the build's ids and
    /// returns the wide child's {index, count} (count in 1..65535) that the traversal hands back
    /// to its leaf callback.
    template <class PackLeaf>
    void build(const std::vector<BuildNode<float>>& built, PackLeaf&& pack_leaf) {
        m_nodes.reserve(built.size() / (N - 1) + 1);
        m_nodes.resize(1);
        collapse(built, pack_leaf, 0, 0, 1);
        // The traversal stack holds at most N - 1 entries per level.
        RT_CHECK(m_depth <= kBvhMaxDepth);
    }

    /// Recomputes every child box bottom-up after the items moved, the topology unchanged:
    /// `leaf_box(index, count)` gives the box of a leaf (as pack_leaf returned it), an inner
    /// child's box is the union of its node's children. Every box then equals the binary
    /// build's box over the same items (the union of the items' boxes: min and max are exact,
    /// so the grouping does not change it).
    template <class LeafBox>
    void refit(LeafBox&& leaf_box) {
        // Children come after their parent in the array: backwards, a node's children are done.
        for (size_t n = m_nodes.size(); n-- > 0;) {
            WideNode<N>& node = m_nodes[n];
            for (int i = 0; i < N; ++i) {
                if (!((node.used >> i) & 1u)) continue;
                const Bounds3f b = node.count[i] > 0 ? leaf_box(node.child[i], uint32_t(node.count[i]))
                                                     : node_bounds(m_nodes[node.child[i]]);
                for (int k = 0; k < 3; ++k) {
                    node.bounds[2 * k][i] = b.lo[k];
                    node.bounds[2 * k + 1][i] = b.hi[k];
                }
            }
        }
    }

    /// The box around everything in the tree (empty for an empty tree).
    Bounds3f bounds() const { return m_nodes.empty() ? Bounds3f{} : node_bounds(m_nodes[0]); }
    bool empty() const { return m_nodes.empty(); }
    size_t size() const { return m_nodes.size(); }
    size_t bytes() const { return m_nodes.size() * sizeof(WideNode<N>); }

    /// Ordered traversal: the children a ray enters are visited nearest first, the others pushed
    /// farthest first with their entry distance and skipped when popped beyond the current `tmax`
    /// (with the slack of geometry.h, as traverse_bvh does). `leaf(index, count)` returns true to
    /// end the traversal (and traverse() then returns true); only leaves change `tmax`.
    /// `prefetch_leaf(index)` asks for a leaf's data as soon as it is chosen. kAllHits: the
    /// entered children are not sorted (an all-hits query visits every one anyway).
    /// kSlabEntryRounding: the exit distance rounded as slab_entry rounds it,
    /// ((plane - org) * rdir) * kSlabExitScale, one more product per axis than the folded
    /// reciprocal: every lane's verdict is then bit for bit the scalar test's (the instance level
    /// uses it so that it culls exactly what the binary top level culled, down to the rays that
    /// start on a surface, whose self-hits at t ~ 1e-8 fall either side of a flat box's exit).
    template <bool kAllHits, bool kSlabEntryRounding = false, class Leaf, class PrefetchLeaf>
    WHITTED_ALWAYS_INLINE bool traverse(const WideRay<N>& r, float t_slack, const float& tmax, Leaf&& leaf,
                                        PrefetchLeaf&& prefetch_leaf) const {
        if (m_nodes.empty()) return false;
        // The culling bound of geometry.h: only leaves change tmax, so it is refreshed after each.
        float cull_tmax = tmax * kRayTmaxScale<float> + t_slack;
        Ref stack[kBvhMaxDepth * (N - 1) + 1];
        int sp = 0;
        Ref cur{0, 0, 0.f};
        auto prefetch = [&](const Ref& c) WHITTED_ALWAYS_INLINE_LAMBDA {
            if (c.count == 0)
                prefetch_node(c.index);
            else
                prefetch_leaf(c.index);
        };
        for (;;) {
            if (cur.count == 0) {
                // N slab tests at once (slab_entry on every lane).
                const WideNode<N>& node = m_nodes[cur.index];
                vf tmin = r.tnear_v;
                vf tmax_v = vf{} + cull_tmax;
                for (int k = 0; k < 3; ++k) {
                    const vf t_near = (node.bounds[r.near_plane[k]] - r.org_v[k]) * r.inv_v[k];
                    vf t_far;
                    if constexpr (kSlabEntryRounding)
                        t_far = (node.bounds[r.far_plane[k]] - r.org_v[k]) * r.inv_v[k] * (vf{} + kSlabExitScale<float>);
                    else
                        t_far = (node.bounds[r.far_plane[k]] - r.org_v[k]) * r.inv_far_v[k];
                    tmin = t_near > tmin ? t_near : tmin;  // NaN compares false: no restriction
                    tmax_v = t_far < tmax_v ? t_far : tmax_v;
                }
                uint32_t mask = simd::lane_mask<N>(tmin <= tmax_v) & node.used;
                if (mask != 0) {
                    float dist[N];
                    std::memcpy(dist, &tmin, sizeof dist);
                    uint32_t i = uint32_t(__builtin_ctz(mask));
                    mask &= mask - 1;
                    if (mask == 0) {  // one child entered: no stack traffic
                        cur = {node.child[i], node.count[i], dist[i]};
                        prefetch(cur);
                        continue;
                    }
                    // Several: pushed and sorted in place on the stack by decreasing entry
                    // distance (insertion sort, stable); the nearest is popped at once. Any-hit
                    // queries skip the sort.
                    const int base = sp;
                    for (;;) {
                        const Ref c{node.child[i], node.count[i], dist[i]};
                        int at = sp++;
                        if constexpr (!kAllHits) {
                            while (at > base && stack[at - 1].dist < c.dist) {
                                stack[at] = stack[at - 1];
                                --at;
                            }
                        }
                        stack[at] = c;
                        if (mask == 0) break;
                        i = uint32_t(__builtin_ctz(mask));
                        mask &= mask - 1;
                    }
                    cur = stack[--sp];
                    prefetch(cur);
                    continue;
                }
            } else {
                if (leaf(cur.index, cur.count)) return true;
                cull_tmax = tmax * kRayTmaxScale<float> + t_slack;  // the leaf may have shortened tmax
            }
            // Pop the next child still in front of the current closest hit.
            for (;;) {
                if (sp == 0) return false;
                const Ref& c = stack[--sp];
                if (c.dist <= cull_tmax) {
                    cur = c;
                    prefetch(cur);
                    break;
                }
            }
        }
    }

private:
    /// The union of a node's used children's boxes.
    static Bounds3f node_bounds(const WideNode<N>& node) {
        Bounds3f b;
        for (int i = 0; i < N; ++i)
            if ((node.used >> i) & 1u)
                b.extend(Bounds3f{Vec3f(node.bounds[0][i], node.bounds[2][i], node.bounds[4][i]),
                                  Vec3f(node.bounds[1][i], node.bounds[3][i], node.bounds[5][i])});
        return b;
    }

    /// One node's children or one leaf: what the traversal stack holds.
    struct Ref {
        uint32_t index;   ///< node index, or the leaf's index as pack_leaf returned it
        uint32_t count;   ///< 0 for a node, else the leaf's count
        float dist;       ///< entry distance of the child's box
    };

    /// Asks for the first four cache lines of a node (all of it for N = 8) at once, so that
    /// their misses overlap instead of following one another through the node test
    /// (prefetching past the end of the array is harmless).
    WHITTED_ALWAYS_INLINE void prefetch_node(uint32_t index) const {
        const char* p = reinterpret_cast<const char*>(m_nodes.data() + index);
        __builtin_prefetch(p);
        __builtin_prefetch(p + 64);
        __builtin_prefetch(p + 128);
        __builtin_prefetch(p + 192);
    }

    /// Writes the wide node `at` for binary node `b`, then, recursively, its subtree. The
    /// children are found by opening, N - 2 times, the inner child with the largest surface area
    /// (the usual greedy collapse; leaves are kept as the SAH build made them). A node's inner
    /// children get consecutive node slots and its leaves consecutive items, so the children
    /// a ray enters lie side by side in memory.
    template <class PackLeaf>
    void collapse(const std::vector<BuildNode<float>>& built, PackLeaf& pack_leaf, uint32_t b, uint32_t at,
                  int depth) {
        m_depth = std::max(m_depth, depth);
        uint32_t kids[N];
        int n = 0;
        if (built[b].count > 0) {
            kids[n++] = b;  // a root that is a leaf
        } else {
            kids[n++] = built[b].index;
            kids[n++] = built[b].index + 1;
        }
        while (n < N) {
            int open = -1;
            float open_area = -1.f;
            for (int i = 0; i < n; ++i)
                if (built[kids[i]].count == 0 && half_area(built[kids[i]].box) > open_area) {
                    open = i;
                    open_area = half_area(built[kids[i]].box);
                }
            if (open < 0) break;
            const uint32_t first = built[kids[open]].index;
            for (int i = n; i > open + 1; --i) kids[i] = kids[i - 1];
            kids[open] = first;
            kids[open + 1] = first + 1;
            ++n;
        }
        WideNode<N> node;
        for (int k = 0; k < 6; ++k)
            for (int i = 0; i < N; ++i) node.bounds[k][i] = (k & 1) ? -kInfinity : kInfinity;
        for (int i = 0; i < N; ++i) {
            node.child[i] = 0;
            node.count[i] = 0;
        }
        node.used = (1u << n) - 1u;
        uint32_t next_node = uint32_t(m_nodes.size());
        for (int i = 0; i < n; ++i) {
            const BuildNode<float>& kid = built[kids[i]];
            for (int k = 0; k < 3; ++k) {
                node.bounds[2 * k][i] = kid.box.lo[k];
                node.bounds[2 * k + 1][i] = kid.box.hi[k];
            }
            if (kid.count > 0) {
                const auto [index, count] = pack_leaf(kid.index, kid.count);
                RT_CHECK(count >= 1u && count <= 0xffffu);
                node.child[i] = index;
                node.count[i] = uint16_t(count);
            } else {
                node.child[i] = next_node++;
            }
        }
        m_nodes[at] = node;
        m_nodes.resize(next_node);
        for (int i = 0; i < n; ++i)
            if (built[kids[i]].count == 0) collapse(built, pack_leaf, kids[i], node.child[i], depth + 1);
    }

    std::vector<WideNode<N>> m_nodes;   ///< root at 0, parents before children
    int m_depth = 0;
};

template <int N>
class WideTriangleBvh {
    static_assert(N == 4 || N == 8, "wide BVH nodes hold 4 or 8 children");
    using vf4 = simd::vfloat<4>;
    using vi4 = simd::vint<4>;

public:
    /// Builds the binary SAH tree over the mesh's triangles (bvh_tree.h) and collapses it.
    WideTriangleBvh(const TrianglePrims<float>& prims, const BvhBuildConfig& config, const WideBvhOptions& options)
        : m_avx2(N == 8 && options.allow_avx2 && simd::cpu_has_avx2()) {
        std::vector<Bounds3f> boxes(prims.size());
        for (uint32_t i = 0; i < prims.size(); ++i) boxes[i] = prims.bounds(i);
        std::vector<uint32_t> ids;
        const std::vector<BuildNode<float>> built = build_bvh(boxes, config, ids);
        m_sah = sah_cost(built, config);
        if (built.empty()) return;
        set_bounds(built[0].box);
        m_triangles = uint32_t(ids.size());
        m_packets.reserve(ids.size() / 2 + 1);
        m_tree.build(built, [&](uint32_t first, uint32_t count) {
            const uint32_t start = pack_leaf(prims, ids, first, count);
            return std::pair<uint32_t, uint32_t>(start, uint32_t(m_packets.size()) - start);
        });
    }

    /// Refits to the mesh's new vertex positions (same triangles, same count): every packet's
    /// vertices rewritten as the build stores them, every box recomputed bottom-up from the
    /// triangles' boxes (WideTree::refit), so boxes and leaf data are those a build with this
    /// topology would have. The SAH figure stays the build's.
    void refit(const Mesh& mesh) {
        const TrianglePrims<float> prims(mesh);
        for (TrianglePacket4& p : m_packets) {
            int32_t last = p.id[0];  // lane 0 always holds a triangle
            for (int lane = 0; lane < 4; ++lane) {
                // A padding lane (id -1) repeats the leaf's last triangle, as pack_leaf stores it.
                const int32_t id = p.id[lane];
                if (id >= 0) last = id;
                store_lane(p, lane, prims.triangle(uint32_t(last)));
            }
        }
        m_tree.refit([&](uint32_t first, uint32_t count) {
            Bounds3f b;
            for (uint32_t k = first; k < first + count; ++k)
                for (int lane = 0; lane < 4; ++lane)
                    if (m_packets[k].id[lane] >= 0) b.extend(prims.bounds(uint32_t(m_packets[k].id[lane])));
            return b;
        });
        set_bounds(m_tree.bounds());
    }

    /// Reports every candidate hit in (tnear, q.tmax] to q.report(t, u, v, triangle); true as
    /// soon as report() asks to stop (an any-hit query answered).
    template <class Query>
    bool traverse(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        if constexpr (N == 8) {
            if (m_avx2) return traverse_avx2(org, dir, tnear, q);
        }
        return traverse_baseline(org, dir, tnear, q);
    }

    /// The same from per-ray constants the caller computed (the instance level, once per ray for
    /// every identity-transform mesh). Inlined into the caller: it runs in the caller's ISA, so
    /// the caller dispatches (wide top level: WideInstanceTree).
    template <class Query>
    WHITTED_ALWAYS_INLINE bool traverse_prepared(const WideRay<N>& r, Query& q) const {
        return m_tree.template traverse<Query::kAllHits>(
            r, r.cull_slack(m_extent), q.tmax,
            [&](uint32_t first, uint32_t count) WHITTED_ALWAYS_INLINE_LAMBDA {
                for (uint32_t p = first; p < first + count; ++p)
                    if (intersect_packet(m_packets[p], r, q)) return true;
                return false;
            },
            [&](uint32_t first) WHITTED_ALWAYS_INLINE_LAMBDA {
                // The leaf's first four cache lines (its first packet and a half).
                const char* p = reinterpret_cast<const char*>(m_packets.data() + first);
                __builtin_prefetch(p);
                __builtin_prefetch(p + 64);
                __builtin_prefetch(p + 128);
                __builtin_prefetch(p + 192);
            });
    }

    Bounds3f bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_tree.bytes() + m_packets.size() * sizeof(TrianglePacket4), m_tree.size(), m_triangles, m_sah};
    }

private:
    // The two compilations of the traversal; everything they call is inlined into them
    // (flatten: the ray set-up and the query's report() too).
    template <class Query>
    WHITTED_FLATTEN bool traverse_baseline(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        const WideRay<N> r(org, dir, tnear);
        return traverse_prepared(r, q);
    }
    template <class Query>
    WHITTED_TARGET_AVX2 WHITTED_FLATTEN bool traverse_avx2(const Vec3f& org, const Vec3f& dir, float tnear,
                                                           Query& q) const {
        const WideRay<N> r(org, dir, tnear);
        return traverse_prepared(r, q);
    }

    /// intersect_triangle (geometry.h) on the four triangles of a packet; hits are reported in
    /// lane order, each one only while its t is still <= the query's tmax.
    template <class Query>
    WHITTED_ALWAYS_INLINE static bool intersect_packet(const TrianglePacket4& p, const WideRay<N>& r, Query& q) {
        // Vertices relative to the origin, sheared and permuted so the ray is +z.
        const vf4 a_z = p.v[0][r.kz] - r.oz, b_z = p.v[1][r.kz] - r.oz, c_z = p.v[2][r.kz] - r.oz;
        const vf4 ax = (p.v[0][r.kx] - r.ox) - r.sx * a_z, ay = (p.v[0][r.ky] - r.oy) - r.sy * a_z;
        const vf4 bx = (p.v[1][r.kx] - r.ox) - r.sx * b_z, by = (p.v[1][r.ky] - r.oy) - r.sy * b_z;
        const vf4 cx = (p.v[2][r.kx] - r.ox) - r.sx * c_z, cy = (p.v[2][r.ky] - r.oy) - r.sy * c_z;
        // Scaled barycentrics; lanes with an edge function of exactly 0 are redone in double.
        vf4 e0 = cx * by - cy * bx;
        vf4 e1 = ax * cy - ay * cx;
        vf4 e2 = bx * ay - by * ax;
        const vf4 zero{};
        if (uint32_t redo = simd::lane_mask<4>((e0 == zero) | (e1 == zero) | (e2 == zero)))
            for (; redo != 0; redo &= redo - 1) {
                const int i = __builtin_ctz(redo);
                e0[i] = float(double(cx[i]) * double(by[i]) - double(cy[i]) * double(bx[i]));
                e1[i] = float(double(ax[i]) * double(cy[i]) - double(ay[i]) * double(cx[i]));
                e2[i] = float(double(bx[i]) * double(ay[i]) - double(by[i]) * double(ax[i]));
            }
        const vi4 mixed_signs = ((e0 < zero) | (e1 < zero) | (e2 < zero)) & ((e0 > zero) | (e1 > zero) | (e2 > zero));
        const vf4 det = e0 + e1 + e2;
        const vi4 inside = ~mixed_signs & (det != zero) & (p.id != vi4{} - 1);
        if (simd::lane_mask<4>(inside) == 0) return false;  // the ray passes by all four (the common case)
        // Distance from the sheared z coordinates interpolated with the scaled barycentrics.
        const vf4 az = r.sz * a_z, bz = r.sz * b_z, cz = r.sz * c_z;
        const vf4 t_scaled = e0 * az + e1 * bz + e2 * cz;
        const vf4 inv_det = 1.f / det;
        const vf4 t = t_scaled * inv_det;
        uint32_t hits = simd::lane_mask<4>(inside & (t > r.tnear) & (t <= q.tmax));
        if (hits == 0) return false;
        const vf4 u = e1 * inv_det, v = e2 * inv_det;
        for (; hits != 0; hits &= hits - 1) {
            const int i = __builtin_ctz(hits);
            if (t[i] <= q.tmax && q.report(t[i], u[i], v[i], uint32_t(p.id[i]))) return true;
        }
        return false;
    }

    /// Appends the triangles of binary leaf slots [first, first + count) as packets of four;
    /// returns the first packet's index.
    uint32_t pack_leaf(const TrianglePrims<float>& prims, const std::vector<uint32_t>& ids, uint32_t first,
                       uint32_t count) {
        const uint32_t start = uint32_t(m_packets.size());
        for (uint32_t base = 0; base < count; base += 4) {
            TrianglePacket4 p;
            for (int lane = 0; lane < 4; ++lane) {
                const uint32_t k = std::min(base + uint32_t(lane), count - 1);
                const uint32_t id = ids[first + k];
                store_lane(p, lane, prims.triangle(id));
                p.id[lane] = base + uint32_t(lane) < count ? int32_t(id) : -1;
            }
            m_packets.push_back(p);
        }
        return start;
    }

    /// Writes a triangle's vertices into one lane of a packet (build and refit).
    static void store_lane(TrianglePacket4& p, int lane, const TriangleVerts<float>& tri) {
        const Vec3f* verts[3] = {&tri.p0, &tri.p1, &tri.p2};
        for (int vtx = 0; vtx < 3; ++vtx)
            for (int axis = 0; axis < 3; ++axis) p.v[vtx][axis][lane] = component(*verts[vtx], axis);
    }

    void set_bounds(const Bounds3f& b) {
        m_bounds = b;
        m_extent = abs_extent(b.lo, b.hi);
    }

    WideTree<N> m_tree;
    std::vector<TrianglePacket4> m_packets;       ///< leaf triangles, four at a time
    Bounds3f m_bounds;
    float m_extent = 0.f;                         ///< largest absolute coordinate (SlabRay culling slack)
    uint32_t m_triangles = 0;
    double m_sah = 0.0;                           ///< SAH cost of the binary tree it was collapsed from
    bool m_avx2 = false;
};

/// The top level of `bvh` over instances as an N-wide tree (the WideTree of the mesh BVHs; a
/// leaf is one instance), the SAH build of bvh_tree.h over the instances' world boxes with one
/// instance per leaf. Its traversal is compiled like the meshes' (baseline and AVX2, dispatched
/// once per ray) with the whole descent inlined into it: `visit(instance, ray)` (the two-level
/// accelerator's entry into one instance) receives the per-ray constants (WideRay) it passes on
/// to identity-transform meshes (WideTriangleBvh::traverse_prepared).
template <int N>
class WideInstanceTree {
public:
    WideInstanceTree() = default;
    /// `boxes[i]` = world box of instance i (two_level.h numbers the instances it traces).
    WideInstanceTree(const std::vector<Bounds3f>& boxes, const WideBvhOptions& options)
        : m_count(uint32_t(boxes.size())), m_avx2(N == 8 && options.allow_avx2 && simd::cpu_has_avx2()) {
        // One instance (the common single-mesh scene): its BLAS tests its own root boxes, so a
        // box test here would only add cost.
        if (boxes.size() < 2) return;
        BvhBuildConfig top;
        top.max_leaf_size = 1;
        const std::vector<BuildNode<float>> built = build_bvh(boxes, top, m_ids);
        m_extent = abs_extent(built[0].box.lo, built[0].box.hi);
        m_tree.build(built, [](uint32_t first, uint32_t count) { return std::pair<uint32_t, uint32_t>(first, count); });
    }

    /// Calls visit(i, ray) for every instance i whose box the ray enters before q.tmax (nearest
    /// first for closest-hit queries); true (and stops) as soon as visit() does.
    template <class Query, class Visit>
    bool traverse(const Vec3f& org, const Vec3f& dir, float tnear, Query& q, Visit&& visit) const {
        if constexpr (N == 8) {
            if (m_avx2) return traverse_avx2(org, dir, tnear, q, visit);
        }
        return traverse_baseline(org, dir, tnear, q, visit);
    }

    size_t bytes() const { return m_tree.bytes() + m_ids.size() * sizeof(uint32_t); }
    size_t nodes() const { return m_tree.size(); }

private:
    template <class Query, class Visit>
    WHITTED_FLATTEN bool traverse_baseline(const Vec3f& org, const Vec3f& dir, float tnear, Query& q,
                                           Visit& visit) const {
        return traverse_impl(org, dir, tnear, q, visit);
    }
    template <class Query, class Visit>
    WHITTED_TARGET_AVX2 WHITTED_FLATTEN bool traverse_avx2(const Vec3f& org, const Vec3f& dir, float tnear,
                                                           Query& q, Visit& visit) const {
        return traverse_impl(org, dir, tnear, q, visit);
    }

    template <class Query, class Visit>
    WHITTED_ALWAYS_INLINE bool traverse_impl(const Vec3f& org, const Vec3f& dir, float tnear, Query& q,
                                             Visit& visit) const {
        if (m_count == 0) return false;
        const WideRay<N> r(org, dir, tnear);
        if (m_tree.empty()) return visit(0u, r);
        return m_tree.template traverse<Query::kAllHits, true>(
            r, r.cull_slack(m_extent), q.tmax,
            [&](uint32_t first, uint32_t count) WHITTED_ALWAYS_INLINE_LAMBDA {
                for (uint32_t k = first; k < first + count; ++k)
                    if (visit(m_ids[k], r)) return true;
                return false;
            },
            [](uint32_t) {});
    }

    WideTree<N> m_tree;             ///< empty for fewer than two instances
    std::vector<uint32_t> m_ids;    ///< leaf slot -> instance
    uint32_t m_count = 0;
    float m_extent = 0.f;           ///< largest absolute coordinate of the instances' boxes
    bool m_avx2 = false;
};

}  // namespace whitted
