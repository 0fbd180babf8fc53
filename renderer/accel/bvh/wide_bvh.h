// Wide BVH over one mesh's triangles (float): the binary SAH tree of bvh_tree.h collapsed into
// nodes of N = 4 or 8 children whose boxes are tested together with SIMD, and leaves of triangles
// stored four at a time (structure of arrays) and tested together. Models: Wald, Benthin &
// Boulos 2008 ("Getting rid of packets", the multi-branching BVH), Embree's BVH4/BVH8 with
// Triangle4 leaves, bvh v2's mini-tree collapse and tinybvh's BVH8_CPU.
//
// Results are those of the binary `bvh:width=2` (up to ties, below):
//   - node test: the conservative slab test of geometry.h (Ize 2013) evaluated on N lanes, with
//     the same near/far plane choice by the direction's sign bit, the same NaN rule, the same
//     exit enlargement (folded into the far plane's reciprocal) and culling slack
//     (tmax * kRayTmaxScale + SlabRay::t_slack): like the scalar test it never culls a box that
//     holds an accepted hit;
//   - leaf test: the watertight test of Woop, Benthin & Wald 2013 (intersect_triangle) with every
//     operation in the same order on four lanes, so t, u, v are bit-identical; lanes whose edge
//     function comes out exactly 0 are recomputed in double as the scalar test does. Hits are
//     reported to the query lane by lane in slot order, each against the query's current tmax,
//     i.e. exactly as the scalar leaf loop would report them.
// Only the order in which leaves are visited differs (nearest child first; and the leaves
// themselves, as the wide build counts triangles in packets), which can change which of two hits
// at exactly the same t wins: a tie the cross-check accepts.
//
// Node tests of an 8-wide tree run as one AVX instruction per operation where the CPU has AVX2
// (runtime dispatch, simd.h), else as two SSE halves (slow: `bvh` then defaults to 4-wide trees,
// which always use SSE).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "renderer/accel/bvh/bvh_tree.h"
#include "renderer/accel/common/geometry.h"
#include "renderer/accel/common/primitives.h"
#include "renderer/accel/common/simd.h"
#include "renderer/accel/common/two_level.h"
#include "renderer/core/error.h"

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

template <int N>
class WideTriangleBvh {
    static_assert(N == 4 || N == 8, "wide BVH nodes hold 4 or 8 children");
    using vf = simd::vfloat<N>;
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
        m_bounds = built[0].box;
        m_extent = abs_extent(m_bounds.lo, m_bounds.hi);
        m_triangles = uint32_t(ids.size());
        m_nodes.reserve(built.size() / (N - 1) + 1);
        m_packets.reserve(ids.size() / 2 + 1);
        m_nodes.resize(1);
        collapse(built, prims, ids, 0, 0, 1);
        // The traversal stack holds at most N - 1 entries per level.
        RT_CHECK(m_depth <= kBvhMaxDepth);
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

    Bounds3f bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_nodes.size() * sizeof(WideNode<N>) + m_packets.size() * sizeof(TrianglePacket4), m_nodes.size(),
                m_triangles, m_sah};
    }

private:
    /// Per-ray constants of the packet triangle test: those of WatertightRay (axis permutation
    /// and shear), with the origin's components already permuted, on four lanes.
    struct PacketRay {
        int kx, ky, kz;
        vf4 ox, oy, oz, sx, sy, sz;
        explicit PacketRay(const WatertightRay<float>& r)
            : kx(r.kx), ky(r.ky), kz(r.kz), ox(vf4{} + component(r.org, r.kx)), oy(vf4{} + component(r.org, r.ky)),
              oz(vf4{} + component(r.org, r.kz)), sx(vf4{} + r.sx), sy(vf4{} + r.sy), sz(vf4{} + r.sz) {}
    };

    /// One node's children or one leaf: what the traversal stack holds.
    struct Ref {
        uint32_t index;   ///< node index, or first packet of a leaf
        uint32_t count;   ///< 0 for a node, else packets in the leaf
        float dist;       ///< entry distance of the child's box
    };

    // The two compilations of the traversal; everything they call is inlined into them
    // (flatten: the ray set-up and the query's report() too, which is measurably faster).
    template <class Query>
    WHITTED_FLATTEN bool traverse_baseline(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        return traverse_impl(org, dir, tnear, q);
    }
    template <class Query>
    WHITTED_TARGET_AVX2 WHITTED_FLATTEN bool traverse_avx2(const Vec3f& org, const Vec3f& dir, float tnear,
                                                           Query& q) const {
        return traverse_impl(org, dir, tnear, q);
    }

    /// Ordered traversal: the children a ray enters are visited nearest first, the others pushed
    /// farthest first with their entry distance and skipped when popped beyond the current tmax
    /// (with the slack of geometry.h, as traverse_bvh does).
    template <class Query>
    WHITTED_ALWAYS_INLINE bool traverse_impl(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        if (m_nodes.empty()) return false;
        // Slab constants (reciprocal direction, sign bits, culling slack) exactly as SlabRay has them.
        const SlabRay<float> slab(org, dir, m_extent);
        // The exit scale of slab_entry is folded into the far plane's reciprocal: the same four
        // roundings (difference, reciprocal, two products), so the same bound (Ize 2013).
        vf org_v[3], inv_v[3], inv_far_v[3];
        int near_plane[3], far_plane[3];
        for (int k = 0; k < 3; ++k) {
            org_v[k] = vf{} + component(slab.org, k);
            inv_v[k] = vf{} + component(slab.inv_dir, k);
            inv_far_v[k] = vf{} + component(slab.inv_dir, k) * kSlabExitScale<float>;
            near_plane[k] = 2 * k + (slab.neg[k] ? 1 : 0);
            far_plane[k] = 2 * k + (slab.neg[k] ? 0 : 1);
        }
        const vf tnear_v = vf{} + tnear;
        const PacketRay pray(WatertightRay<float>(org, dir));

        // The culling bound of geometry.h: only leaves change q.tmax, so it is refreshed after each.
        float cull_tmax = q.tmax * kRayTmaxScale<float> + slab.t_slack;
        Ref stack[kBvhMaxDepth * (N - 1) + 1];
        int sp = 0;
        Ref cur{0, 0, 0.f};
        for (;;) {
            if (cur.count == 0) {
                // N slab tests at once (slab_entry on every lane).
                const WideNode<N>& node = m_nodes[cur.index];
                vf tmin = tnear_v;
                vf tmax = vf{} + cull_tmax;
                for (int k = 0; k < 3; ++k) {
                    const vf t_near = (node.bounds[near_plane[k]] - org_v[k]) * inv_v[k];
                    const vf t_far = (node.bounds[far_plane[k]] - org_v[k]) * inv_far_v[k];
                    tmin = t_near > tmin ? t_near : tmin;  // NaN compares false: no restriction
                    tmax = t_far < tmax ? t_far : tmax;
                }
                uint32_t mask = simd::lane_mask<N>(tmin <= tmax) & node.used;
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
                        const Ref r{node.child[i], node.count[i], dist[i]};
                        int at = sp++;
                        if constexpr (!Query::kAllHits) {
                            while (at > base && stack[at - 1].dist < r.dist) {
                                stack[at] = stack[at - 1];
                                --at;
                            }
                        }
                        stack[at] = r;
                        if (mask == 0) break;
                        i = uint32_t(__builtin_ctz(mask));
                        mask &= mask - 1;
                    }
                    cur = stack[--sp];
                    prefetch(cur);
                    continue;
                }
            } else {
                for (uint32_t p = cur.index; p < cur.index + cur.count; ++p)
                    if (intersect_packet(m_packets[p], pray, tnear, q)) return true;
                cull_tmax = q.tmax * kRayTmaxScale<float> + slab.t_slack;  // the leaf may have shortened tmax
            }
            // Pop the next child still in front of the current closest hit.
            for (;;) {
                if (sp == 0) return false;
                const Ref& r = stack[--sp];
                if (r.dist <= cull_tmax) {
                    cur = r;
                    prefetch(cur);
                    break;
                }
            }
        }
    }

    /// Asks for the first four cache lines of the node (all of it for N = 8) or of the leaf's
    /// packets at once, so that their misses overlap instead of following one another through
    /// the node test (prefetching past the end of the array is harmless).
    WHITTED_ALWAYS_INLINE void prefetch(const Ref& r) const {
        const char* p = r.count == 0 ? reinterpret_cast<const char*>(m_nodes.data() + r.index)
                                     : reinterpret_cast<const char*>(m_packets.data() + r.index);
        __builtin_prefetch(p);
        __builtin_prefetch(p + 64);
        __builtin_prefetch(p + 128);
        __builtin_prefetch(p + 192);
    }

    /// intersect_triangle (geometry.h) on the four triangles of a packet; hits are reported in
    /// lane order, each one only while its t is still <= the query's tmax.
    template <class Query>
    WHITTED_ALWAYS_INLINE bool intersect_packet(const TrianglePacket4& p, const PacketRay& r, float tnear,
                                                Query& q) const {
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
        uint32_t hits = simd::lane_mask<4>(inside & (t > tnear) & (t <= q.tmax));
        if (hits == 0) return false;
        const vf4 u = e1 * inv_det, v = e2 * inv_det;
        for (; hits != 0; hits &= hits - 1) {
            const int i = __builtin_ctz(hits);
            if (t[i] <= q.tmax && q.report(t[i], u[i], v[i], uint32_t(p.id[i]))) return true;
        }
        return false;
    }

    /// Writes the wide node `at` for binary node `b`, then, recursively, its subtree. The
    /// children are found by opening, N - 2 times, the inner child with the largest surface area
    /// (the usual greedy collapse; leaves are kept as the SAH build made them). A node's inner
    /// children get consecutive node slots and its leaves consecutive packets, so the children
    /// a ray enters lie side by side in memory.
    void collapse(const std::vector<BuildNode<float>>& built, const TrianglePrims<float>& prims,
                  const std::vector<uint32_t>& ids, uint32_t b, uint32_t at, int depth) {
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
                node.child[i] = pack_leaf(prims, ids, kid.index, kid.count);
                const uint32_t packets = uint32_t(m_packets.size()) - node.child[i];
                RT_CHECK(packets <= 0xffffu);
                node.count[i] = uint16_t(packets);
            } else {
                node.child[i] = next_node++;
            }
        }
        m_nodes[at] = node;
        m_nodes.resize(next_node);
        for (int i = 0; i < n; ++i)
            if (built[kids[i]].count == 0) collapse(built, prims, ids, kids[i], node.child[i], depth + 1);
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
                const TriangleVerts<float>& tri = prims.triangle(id);
                const Vec3f* verts[3] = {&tri.p0, &tri.p1, &tri.p2};
                for (int vtx = 0; vtx < 3; ++vtx)
                    for (int axis = 0; axis < 3; ++axis) p.v[vtx][axis][lane] = component(*verts[vtx], axis);
                p.id[lane] = base + uint32_t(lane) < count ? int32_t(id) : -1;
            }
            m_packets.push_back(p);
        }
        return start;
    }

    std::vector<WideNode<N>> m_nodes;             ///< root at 0, parents before children
    std::vector<TrianglePacket4> m_packets;       ///< leaf triangles, four at a time
    Bounds3f m_bounds;
    float m_extent = 0.f;                         ///< largest absolute coordinate (SlabRay culling slack)
    uint32_t m_triangles = 0;
    int m_depth = 0;
    double m_sah = 0.0;                           ///< SAH cost of the binary tree it was collapsed from
    bool m_avx2 = false;
};

}  // namespace whitted
