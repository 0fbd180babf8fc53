#include "accel/bvh/bvh_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "accel/bvh/wide_bvh.h"
#include "accel/bvh/two_level.h"

namespace whitted {

namespace {

/// Ray data a volume's test needs: slab constants for boxes and spheres, 7 projections for k-DOPs.
template <typename T, typename V>
struct VolumeRay {
    using type = SlabRay<T>;
    static type make(const SlabRay<T>& r) { return r; }
};
template <typename T>
struct VolumeRay<T, KdopVolume<T>> {
    using type = KdopRay<T>;
    static type make(const SlabRay<T>& r) { return KdopRay<T>(r); }
};

/// A BVH over a primitive set P (triangles of one mesh, or the scene's spheres), with bounding
/// volume V. Primitives are stored in leaf order.
template <typename T, typename V, typename P>
class PrimBvh {
public:
    PrimBvh(P prims, const BvhBuildConfig& config) : m_prims(std::move(prims)) {
        std::vector<Bounds3<T>> boxes(m_prims.size());
        for (uint32_t i = 0; i < m_prims.size(); ++i) boxes[i] = m_prims.bounds(i);
        std::vector<BuildNode<T>> built = build_bvh(boxes, config, m_ids);
        m_sah = sah_cost(built, config);
        // Primitives in leaf order: a leaf reads a contiguous run.
        m_prims.reorder(m_ids);
        fit(built);
    }

    /// Refits to the mesh's new vertex positions (same triangles, same count): the topology and
    /// the leaf order stay, the node volumes are fitted again by fit() from boxes recomputed
    /// bottom-up, so each volume encloses its subtree exactly as a build's would. The SAH figure
    /// stays the build's.
    void refit(const Mesh& mesh)
        requires std::is_same_v<P, TrianglePrims<T>>
    {
        m_prims = P(mesh);
        m_prims.reorder(m_ids);
        // The builder's view of the tree, children after their parent: a leaf's box is the union
        // of its primitives' boxes, an inner node's the union of its children's, which is what
        // build_bvh computes (min and max are exact: the grouping does not change the box).
        std::vector<BuildNode<T>> built(m_nodes.size());
        for (size_t i = built.size(); i-- > 0;) {
            BuildNode<T>& b = built[i];
            b.index = m_nodes[i].index;
            b.count = m_nodes[i].count;
            if (b.count > 0) {
                b.begin = b.index;
                b.end = b.index + b.count;
                for (uint32_t k = b.begin; k < b.end; ++k) b.box.extend(m_prims.bounds(k));
            } else {
                const BuildNode<T>& left = built[b.index];
                const BuildNode<T>& right = built[b.index + 1];
                b.begin = left.begin;
                b.end = right.end;
                b.box = left.box;
                b.box.extend(right.box);
            }
        }
        fit(built);
    }

    template <class Query>
    bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q) const {
        const typename P::RayData pr = P::ray_data(org, dir);
        const auto vray = VolumeRay<T, V>::make(SlabRay<T>(org, dir, m_extent));
        bool stop = false;
        traverse_bvh(m_nodes, vray, tnear, q.tmax, [&](uint32_t first, uint32_t count) {
            for (uint32_t i = first; i < first + count; ++i)
                if (m_prims.intersect(pr, i, m_ids[i], tnear, q)) return stop = true;
            return false;
        });
        return stop;
    }

    Bounds3<T> bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_nodes.size() * sizeof(m_nodes[0]) + m_prims.bytes() + m_ids.size() * 4, m_nodes.size(), m_ids.size(),
                m_sah};
    }

private:
    /// Converts the builder's boxes into the node volume V and takes the root's box (build and
    /// refit alike; m_prims in leaf order).
    void fit(const std::vector<BuildNode<T>>& built) {
        if (!built.empty()) m_bounds = built[0].box;
        m_extent = abs_extent(m_bounds.lo, m_bounds.hi);
        m_nodes.resize(built.size());
        if constexpr (std::is_same_v<V, AabbVolume<T>>) {
            for (size_t i = 0; i < built.size(); ++i) m_nodes[i] = {{built[i].box.lo, built[i].box.hi}, built[i].index, built[i].count};
        } else if constexpr (std::is_same_v<V, SphereVolume<T>>) {
            // Centre at the box centre; radius reaching every point of the primitives below the
            // node (tighter than the box's circumsphere), enlarged so the float test stays
            // conservative.
            tbb::parallel_for(size_t(0), built.size(), [&](size_t i) {
                const BuildNode<T>& b = built[i];
                const Vec3<T> c = b.box.center();
                T r2 = 0;
                for (uint32_t k = b.begin; k < b.end; ++k) r2 = std::max(r2, m_prims.max_distance2(k, c));
                const T r = std::sqrt(r2) * (T(1) + T(16) * rounding_gamma<T>(1)) +
                            T(4) * rounding_gamma<T>(1) * (std::fabs(c.x) + std::fabs(c.y) + std::fabs(c.z));
                m_nodes[i] = {{c, r}, b.index, b.count};
            });
        } else {
            // k-DOPs bottom-up: children always come after their parent in the array.
            for (size_t i = built.size(); i-- > 0;) {
                const BuildNode<T>& b = built[i];
                KdopVolume<T> d;
                if (b.count > 0) {
                    d = m_prims.kdop(b.index);
                    for (uint32_t k = b.index + 1; k < b.index + b.count; ++k) join(d, m_prims.kdop(k));
                } else {
                    d = m_nodes[b.index].volume;
                    join(d, m_nodes[b.index + 1].volume);
                }
                m_nodes[i] = {d, b.index, b.count};
            }
        }
    }

    static void join(KdopVolume<T>& a, const KdopVolume<T>& b) {
        for (int k = 0; k < kKdopSlabs; ++k) {
            a.lo[k] = std::min(a.lo[k], b.lo[k]);
            a.hi[k] = std::max(a.hi[k], b.hi[k]);
        }
    }

    std::vector<BvhNode<V>> m_nodes;
    P m_prims;
    std::vector<uint32_t> m_ids;   ///< slot -> original primitive index
    Bounds3<T> m_bounds;
    T m_extent = 0;                ///< largest absolute coordinate (SlabRay culling slack)
    double m_sah = 0.0;
};

/// No structure: every primitive, in index order.
template <typename T, typename P>
class PrimList {
public:
    explicit PrimList(P prims) : m_prims(std::move(prims)) {
        for (uint32_t i = 0; i < m_prims.size(); ++i) m_bounds.extend(m_prims.bounds(i));
    }

    template <class Query>
    bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q) const {
        const typename P::RayData pr = P::ray_data(org, dir);
        for (uint32_t i = 0; i < m_prims.size(); ++i)
            if (m_prims.intersect(pr, i, i, tnear, q)) return true;
        return false;
    }

    Bounds3<T> bounds() const { return m_bounds; }
    BlasStats stats() const { return {m_prims.bytes(), 0, m_prims.size(), 0.0}; }

private:
    P m_prims;
    Bounds3<T> m_bounds;
};

template <typename T, typename V>
std::unique_ptr<Accelerator> make_bvh(const char* name, const Scene& scene, const SurfaceFilter& filter,
                                      const BvhBuildConfig& build, bool flatten = true) {
    using Blas = PrimBvh<T, V, TrianglePrims<T>>;
    using SphereBlas = PrimBvh<T, V, AnalyticPrims<T>>;
    // Spheres: small leaves (a sphere test costs about as much as a node test).
    BvhBuildConfig sphere_build = build;
    sphere_build.max_leaf_size = std::min(build.max_leaf_size, 2);
    // The mesh builder outlives this call (update() may build a mesh again): settings by value.
    return std::make_unique<TwoLevelAccelerator<T, Blas, SphereBlas>>(
        name, scene, filter, [build](const Mesh& m) { return Blas(TrianglePrims<T>(m), build); },
        [&](AnalyticPrims<T>&& s) { return SphereBlas(std::move(s), sphere_build); }, true, flatten);
}

/// `bvh` with N-wide mesh BVHs and an N-wide top level over instances (float boxes); the
/// spheres keep the binary tree.
template <int N>
std::unique_ptr<Accelerator> make_wide_bvh(const Scene& scene, const SurfaceFilter& filter, const BvhBuildConfig& build,
                                           const WideBvhOptions& options, bool flatten) {
    using Blas = WideTriangleBvh<N>;
    using SphereBlas = PrimBvh<float, AabbVolume<float>, AnalyticPrims<float>>;
    using Top = WideInstanceTree<N>;
    BvhBuildConfig sphere_build = build;
    sphere_build.max_leaf_size = std::min(build.max_leaf_size, 2);
    // The mesh and top-level builders outlive this call (update()): settings by value.
    return std::make_unique<TwoLevelAccelerator<float, Blas, SphereBlas, Top>>(
        "bvh", scene, filter, [build, options](const Mesh& m) { return Blas(TrianglePrims<float>(m), build, options); },
        [&](AnalyticPrims<float>&& s) { return SphereBlas(std::move(s), sphere_build); },
        [options](const std::vector<Bounds3f>& boxes) { return Top(boxes, options); }, flatten);
}

template <typename T>
std::unique_ptr<Accelerator> make_brute(const Scene& scene, const SurfaceFilter& filter) {
    using Blas = PrimList<T, TrianglePrims<T>>;
    using SphereBlas = PrimList<T, AnalyticPrims<T>>;
    return std::make_unique<TwoLevelAccelerator<T, Blas, SphereBlas>>(
        "brute", scene, filter, [](const Mesh& m) { return Blas(TrianglePrims<T>(m)); },
        [](AnalyticPrims<T>&& s) { return SphereBlas(std::move(s)); }, false);
}

}  // namespace

std::unique_ptr<Accelerator> create_bvh_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                    const BvhConfig& config) {
    const bool dbl = config.precision == Precision::Double;
    if (!dbl && config.volume == BoundingVolume::Aabb && config.width != 2) {
        const WideBvhOptions options{config.allow_avx2};
        // Without AVX2 an 8-wide node test is two SSE halves: 4-wide trees are faster there.
        const int width = config.width != 0 ? config.width : (config.allow_avx2 && simd::cpu_has_avx2() ? 8 : 4);
        return width == 4 ? make_wide_bvh<4>(scene, filter, config.build, options, config.flatten)
                          : make_wide_bvh<8>(scene, filter, config.build, options, config.flatten);
    }
    if (config.volume == BoundingVolume::Sphere)
        return dbl ? make_bvh<double, SphereVolume<double>>("bvh", scene, filter, config.build, config.flatten)
                   : make_bvh<float, SphereVolume<float>>("bvh", scene, filter, config.build, config.flatten);
    return dbl ? make_bvh<double, AabbVolume<double>>("bvh", scene, filter, config.build, config.flatten)
               : make_bvh<float, AabbVolume<float>>("bvh", scene, filter, config.build, config.flatten);
}

std::unique_ptr<Accelerator> create_kdop_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                     const KdopConfig& config) {
    return make_bvh<float, KdopVolume<float>>("kdop", scene, filter, config.build);
}

std::unique_ptr<Accelerator> create_brute_force_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                            const BruteForceConfig& config) {
    return config.precision == Precision::Double ? make_brute<double>(scene, filter) : make_brute<float>(scene, filter);
}

}  // namespace whitted
