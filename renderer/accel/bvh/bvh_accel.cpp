#include "renderer/accel/bvh/bvh_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "renderer/accel/common/two_level.h"

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

/// Outward-rounded k-DOP of one triangle (the diagonal projections round in float).
template <typename T>
KdopVolume<T> triangle_kdop(const TriangleVerts<T>& tri) {
    KdopVolume<T> d;
    for (int k = 0; k < kKdopSlabs; ++k) {
        d.lo[k] = std::numeric_limits<T>::infinity();
        d.hi[k] = -std::numeric_limits<T>::infinity();
        for (const Vec3<T>& p : {tri.p0, tri.p1, tri.p2}) {
            const T proj = kdop_project(k, p);
            const T err = k < 3 ? T(0) : rounding_gamma<T>(3) * (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z));
            d.lo[k] = std::min(d.lo[k], proj - err);
            d.hi[k] = std::max(d.hi[k], proj + err);
        }
    }
    return d;
}

/// A BVH over one mesh's triangles, with bounding volume V. Triangles are stored in leaf order.
template <typename T, typename V>
class TriangleBvh {
public:
    TriangleBvh(const Mesh& mesh, const BvhBuildConfig& config) {
        std::vector<TriangleVerts<T>> tris = mesh_triangles<T>(mesh);
        std::vector<Bounds3<T>> boxes(tris.size());
        for (size_t i = 0; i < tris.size(); ++i) boxes[i] = triangle_bounds(tris[i]);
        std::vector<BuildNode<T>> built = build_bvh(boxes, config, m_prims);
        m_sah = sah_cost(built, config);
        // Triangles in leaf order: a leaf reads a contiguous run.
        m_tris.resize(tris.size());
        for (size_t i = 0; i < m_prims.size(); ++i) m_tris[i] = tris[m_prims[i]];
        if (!built.empty()) m_bounds = built[0].box;
        fit(built);
    }

    template <class Query>
    bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q) const {
        const WatertightRay<T> wr(org, dir);
        const auto vray = VolumeRay<T, V>::make(SlabRay<T>(org, dir));
        bool stop = false;
        traverse_bvh(m_nodes, vray, tnear, q.tmax, [&](uint32_t first, uint32_t count) {
            for (uint32_t i = first; i < first + count; ++i) {
                const TriangleVerts<T>& tri = m_tris[i];
                T t, u, v;
                if (intersect_triangle(wr, tri.p0, tri.p1, tri.p2, tnear, q.tmax, t, u, v) &&
                    q.report(t, u, v, m_prims[i]))
                    return stop = true;
            }
            return false;
        });
        return stop;
    }

    Bounds3<T> bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_nodes.size() * sizeof(m_nodes[0]) + m_tris.size() * sizeof(m_tris[0]) + m_prims.size() * 4,
                m_nodes.size(), m_prims.size(), m_sah};
    }

private:
    /// Converts the builder's boxes into the node volume V.
    void fit(const std::vector<BuildNode<T>>& built) {
        m_nodes.resize(built.size());
        if constexpr (std::is_same_v<V, AabbVolume<T>>) {
            for (size_t i = 0; i < built.size(); ++i) m_nodes[i] = {{built[i].box.lo, built[i].box.hi}, built[i].index, built[i].count};
        } else if constexpr (std::is_same_v<V, SphereVolume<T>>) {
            // Centre at the box centre; radius reaching every vertex below the node (tighter than
            // the box's circumsphere), enlarged so the float test stays conservative.
            tbb::parallel_for(size_t(0), built.size(), [&](size_t i) {
                const BuildNode<T>& b = built[i];
                const Vec3<T> c = b.box.center();
                T r2 = 0;
                for (uint32_t k = b.begin; k < b.end; ++k)
                    for (const Vec3<T>& p : {m_tris[k].p0, m_tris[k].p1, m_tris[k].p2}) r2 = std::max(r2, dot(p - c, p - c));
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
                    d = triangle_kdop(m_tris[b.index]);
                    for (uint32_t k = b.index + 1; k < b.index + b.count; ++k) join(d, triangle_kdop(m_tris[k]));
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
    std::vector<TriangleVerts<T>> m_tris;
    std::vector<uint32_t> m_prims;
    Bounds3<T> m_bounds;
    double m_sah = 0.0;
};

/// No structure: every triangle of the mesh, in index order.
template <typename T>
class TriangleList {
public:
    explicit TriangleList(const Mesh& mesh) : m_tris(mesh_triangles<T>(mesh)) {
        for (const TriangleVerts<T>& t : m_tris) m_bounds.extend(triangle_bounds(t));
    }

    template <class Query>
    bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q) const {
        const WatertightRay<T> wr(org, dir);
        for (uint32_t i = 0; i < uint32_t(m_tris.size()); ++i) {
            T t, u, v;
            if (intersect_triangle(wr, m_tris[i].p0, m_tris[i].p1, m_tris[i].p2, tnear, q.tmax, t, u, v) &&
                q.report(t, u, v, i))
                return true;
        }
        return false;
    }

    Bounds3<T> bounds() const { return m_bounds; }
    BlasStats stats() const { return {m_tris.size() * sizeof(m_tris[0]), 0, m_tris.size(), 0.0}; }

private:
    std::vector<TriangleVerts<T>> m_tris;
    Bounds3<T> m_bounds;
};

template <typename T, typename V>
std::unique_ptr<Accelerator> make_bvh(const char* name, const Scene& scene, const SurfaceFilter& filter,
                                      const BvhBuildConfig& build) {
    using Blas = TriangleBvh<T, V>;
    return std::make_unique<TwoLevelAccelerator<T, Blas>>(
        name, scene, filter, [&](const Mesh& m) { return Blas(m, build); }, true);
}

}  // namespace

std::unique_ptr<Accelerator> create_bvh_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                    const BvhConfig& config) {
    const bool dbl = config.precision == Precision::Double;
    if (config.volume == BoundingVolume::Sphere)
        return dbl ? make_bvh<double, SphereVolume<double>>("bvh", scene, filter, config.build)
                   : make_bvh<float, SphereVolume<float>>("bvh", scene, filter, config.build);
    return dbl ? make_bvh<double, AabbVolume<double>>("bvh", scene, filter, config.build)
               : make_bvh<float, AabbVolume<float>>("bvh", scene, filter, config.build);
}

std::unique_ptr<Accelerator> create_kdop_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                     const KdopConfig& config) {
    return make_bvh<float, KdopVolume<float>>("kdop", scene, filter, config.build);
}

std::unique_ptr<Accelerator> create_brute_force_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                            const BruteForceConfig& config) {
    if (config.precision == Precision::Double)
        return std::make_unique<TwoLevelAccelerator<double, TriangleList<double>>>(
            "brute", scene, filter, [](const Mesh& m) { return TriangleList<double>(m); }, false);
    return std::make_unique<TwoLevelAccelerator<float, TriangleList<float>>>(
        "brute", scene, filter, [](const Mesh& m) { return TriangleList<float>(m); }, false);
}

}  // namespace whitted
