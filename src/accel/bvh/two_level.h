// Two-level acceleration shared by the in-house backends, mirroring the Embree backend's layout:
// one bottom-level structure (BLAS) per mesh in object space, and a top level over the instances
// that transforms the ray into each instance's object space (t is unchanged by an affine map of
// origin and direction). The top level (the `Top` parameter) is the binary SAH BVH of
// bvh_tree.h over the instances' world boxes (BinaryInstanceTree; for the brute-force oracle a
// plain loop), or `bvh`'s 8/4-wide tree (WideInstanceTree, bvh/wide_bvh.h). The scene's analytic
// spheres are one more structure of the backend's own kind (SphereBlas, built over AnalyticPrims in
// world space), traced beside the top level with the world-space ray; infinite planes are added
// outside (planes.h). With `flatten` (the default for float structures), the meshes that exactly
// one instance uses (with a transform that keeps orientation) are put in world space into one
// shared BLAS instead, whose hits report the instance, mesh and primitive they came from; meshes
// used more than once stay instanced. Every float backend flattens alike, so they still agree with
// the brute-force oracle hit for hit; double-precision structures never flatten (world-space
// vertices would be rounded to float).
//
// update() (accelerator.h) refits the BLAS of each deformed mesh, or builds it again with the
// kept builder where the BLAS type cannot refit, recomputes the moved instances' transforms and
// builds the top level again over the new world boxes; the spheres and the flat BLAS (static by
// flatten.h) stay. Refit keeps a tree's shape, so its hits are a new build's as long as its
// volumes enclose their subtrees and the leaves see the same vertices: the tie rule of queries.h
// makes the closest hit independent of the shape.
//
// A BLAS type provides
//   template <class Query> bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q) const;
//     reports every candidate hit in (tnear, q.tmax] to q.report(...) and returns true as soon
//     as report() does;
//   Bounds3<T> bounds() const; BlasStats stats() const;
// and optionally
//   template <class Query> bool traverse_prepared(const PreparedRay& r, Query& q) const;
//     the same from the per-ray constants the top level hands to visit() (PreparedRay is the
//     top level's type, e.g. WideRay<N>; constructible from (org, dir, tnear)): identity
//     instances reuse the world ray's, transformed ones build their own;
//   void refit(const Mesh& mesh);
//     the mesh's vertices moved (same triangles): brings the structure up to date in place,
//     answering every query as a build over the new vertices would (update(); without it the
//     mesh is built again).
// A top level type provides
//   template <class Query, class Visit> bool traverse(org, dir, tnear, Query& q, Visit&& visit) const;
//     calls visit(i, prepared) for the instances i (numbered as the boxes it was built from)
//     whose box the ray may enter before q.tmax, true (and stops) as soon as visit() does;
//   size_t bytes() const; size_t nodes() const.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "accel/accelerator.h"
#include "accel/bvh/bvh_tree.h"
#include "accel/common/flatten.h"
#include "accel/common/geometry.h"
#include "accel/common/primitives.h"
#include "accel/common/queries.h"
#include "accel/common/simd.h"
#include "core/parallel.h"
#include "scene/scene.h"

namespace whitted {

/// Size figures of one bottom-level structure.
struct BlasStats {
    size_t bytes = 0;
    size_t nodes = 0;        ///< nodes, cells or voxels
    size_t references = 0;   ///< primitive references (> triangles when cells duplicate them)
    double sah_cost = 0.0;   ///< SAH cost of the tree (0 when it does not apply), area-weighted by triangles
};

/// Row-major 3x4 affine transform in precision T.
template <typename T>
struct Affine {
    T m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    bool identity = true;
    explicit Affine(const Mat4d& x = Mat4d::identity()) {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) m[r * 4 + c] = T(x(r, c));
        identity = x == Mat4d::identity();
    }
    Vec3<T> point(const Vec3<T>& p) const {
        return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
    }
    Vec3<T> vector(const Vec3<T>& v) const {
        return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                m[8] * v.x + m[9] * v.y + m[10] * v.z};
    }
};

/// What a top level without per-ray constants of its own hands to visit(): the BLAS takes the
/// ray as origin and direction.
struct NoPreparedRay {};

/// The instance level as the binary SAH tree of bvh_tree.h (one instance per leaf, slab-tested
/// boxes), or, with `tree` false, a plain loop over the instances in order (the brute-force
/// oracle).
template <typename T>
class BinaryInstanceTree {
public:
    BinaryInstanceTree() = default;
    BinaryInstanceTree(const std::vector<Bounds3<T>>& boxes, bool tree) : m_count(uint32_t(boxes.size())) {
        // One instance (the common single-mesh scene): its BLAS tests its own root boxes, so the
        // top level's set-up and box test would only add cost.
        if (!tree || boxes.size() < 2) return;
        BvhBuildConfig top;
        top.max_leaf_size = 1;
        std::vector<BuildNode<T>> built = build_bvh(boxes, top, m_ids);
        m_nodes.reserve(built.size());
        for (const BuildNode<T>& n : built) m_nodes.push_back({AabbVolume<T>{n.box.lo, n.box.hi}, n.index, n.count});
        m_extent = abs_extent(m_nodes[0].volume.lo, m_nodes[0].volume.hi);
    }

    template <class Query, class Visit>
    bool traverse(const Vec3<T>& org, const Vec3<T>& dir, T tnear, Query& q, Visit&& visit) const {
        if (m_nodes.empty()) {
            for (uint32_t k = 0; k < m_count; ++k)
                if (visit(k, NoPreparedRay{})) return true;
            return false;
        }
        const SlabRay<T> slab(org, dir, m_extent);
        bool stop = false;
        traverse_bvh(m_nodes, slab, tnear, q.tmax, [&](uint32_t first, uint32_t count) {
            for (uint32_t k = 0; k < count; ++k)
                if (visit(m_ids[first + k], NoPreparedRay{})) return stop = true;
            return false;
        });
        return stop;
    }

    size_t bytes() const { return m_nodes.size() * sizeof(m_nodes[0]) + m_ids.size() * sizeof(uint32_t); }
    size_t nodes() const { return m_nodes.size(); }

private:
    std::vector<BvhNode<AabbVolume<T>>> m_nodes;  ///< empty: loop over all instances
    std::vector<uint32_t> m_ids;                  ///< leaf slot -> instance
    uint32_t m_count = 0;
    T m_extent = 0;                               ///< largest absolute coordinate of the boxes (culling slack)
};

/// The accelerator built from one BLAS per mesh, a top level over instances and one structure
/// over the scene's spheres.
template <typename T, typename Blas, typename SphereBlas, typename Top = BinaryInstanceTree<T>>
class TwoLevelAccelerator final : public Accelerator {
public:
    using Accelerator::intersect;  // the batch query: the default loop (no packet traversal here)
    using Accelerator::transmittance;
    RayOffsetPolicy ray_offset() const override {
        return std::is_same_v<T, double> ? kDoubleRayOffset : kFloatRayOffset;
    }
    using BlasBuilder = std::function<Blas(const Mesh&)>;
    using SphereBuilder = std::function<SphereBlas(AnalyticPrims<T>&&)>;
    using TopBuilder = std::function<Top(const std::vector<Bounds3<T>>&)>;

    /// With the binary top level: `bvh_top` false = loop over all instances (the brute-force
    /// oracle).
    TwoLevelAccelerator(std::string name, const Scene& scene, const SurfaceFilter& filter, const BlasBuilder& build_blas,
                        const SphereBuilder& build_spheres, bool bvh_top, bool flatten = true)
        : TwoLevelAccelerator(std::move(name), scene, filter, build_blas, build_spheres,
                              [bvh_top](const std::vector<Bounds3<T>>& boxes) { return Top(boxes, bvh_top); }, flatten) {}

    /// Builds the BLASes in parallel over meshes (each build is deterministic), then the top
    /// level over the instances' world boxes and the sphere structure (when the scene has
    /// spheres). `flatten`: single-use meshes share one world-space BLAS (see the top).
    /// `build_blas` and `build_top` are kept for update(): they must not refer to the caller's
    /// locals.
    TwoLevelAccelerator(std::string name, const Scene& scene, const SurfaceFilter& filter, const BlasBuilder& build_blas,
                        const SphereBuilder& build_spheres, const TopBuilder& build_top, bool flatten = true)
        : m_name(std::move(name)), m_scene(scene), m_filter(filter), m_build_blas(build_blas), m_build_top(build_top) {
        const auto start = std::chrono::steady_clock::now();
        // Spheres: world space, each with its own geometry id and filter flags.
        AnalyticPrims<T> spheres(scene, filter);
        if (spheres.size() > 0) m_spheres = std::make_unique<SphereBlas>(build_spheres(std::move(spheres)));
        // Which instances are flattened (none unless at least two would share the flat BLAS).
        m_flat = flattened_instances(scene, flatten && std::is_same_v<T, float>);
        m_mesh_flat.assign(scene.meshes.size(), 0);
        for (size_t i = 0; i < m_flat.size(); ++i)
            if (m_flat[i]) m_mesh_flat[scene.instances[i].mesh] = 1;
        // Bottom level: one structure per instanced mesh that has triangles, and the flat one,
        // meshes in parallel on the worker pool (whose fork and join ThreadSanitizer sees, and
        // whose workers build in the same floating-point mode as the caller).
        m_blas.resize(scene.meshes.size());
        WorkerPool(0).for_each(scene.meshes.size(), [&](size_t m, int) {
            if (scene.meshes[m].triangle_count() > 0 && !m_mesh_flat[m])
                m_blas[m] = std::make_unique<Blas>(build_blas(scene.meshes[m]));
        });
        if (std::find(m_flat.begin(), m_flat.end(), 1) != m_flat.end()) {
            // World-space vertices (transformed in double, rounded once), each triangle's origin kept.
            Mesh merged;
            for (size_t i = 0; i < m_flat.size(); ++i) {
                if (!m_flat[i]) continue;
                const Instance& inst = scene.instances[i];
                const Mesh& mesh = scene.meshes[inst.mesh];
                const auto base = uint32_t(merged.positions.size());
                for (const Vec3f& p : mesh.positions) merged.positions.push_back(Vec3f(inst.world_from_object.apply_point(Vec3d(p))));
                for (uint32_t idx : mesh.indices) merged.indices.push_back(base + idx);
                const InstanceContext ctx{inst.mesh, uint32_t(i), filter.mesh_flags(inst.mesh)};
                for (uint32_t p = 0; p < mesh.triangle_count(); ++p) m_flat_prims.push_back({ctx, p});
            }
            m_flat_blas = std::make_unique<Blas>(build_blas(merged));
        }
        // Instances with their inverse transforms and world boxes; the flat BLAS is one more
        // entry with the identity transform.
        if (m_flat_blas) m_instances.push_back(InstanceData{Affine<T>(), kFlatMesh, kInvalidId, 0});
        for (size_t i = 0; i < scene.instances.size(); ++i)
            if (m_blas[scene.instances[i].mesh]) m_instances.push_back(instance_data(uint32_t(i)));
        m_top = build_top(world_boxes());
        m_stats.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        size_stats();
    }

    /// Refits the BLAS of each mesh in `update.meshes` to the scene's new vertices (builds it
    /// again where the BLAS type has no refit()), takes the new transforms of the instances in
    /// `update.instances`, and builds the top level again over the new world boxes; spheres and
    /// the flat BLAS are left as they are. False, changing nothing, when the update names a mesh
    /// or instance out of range or in the flat BLAS (flatten.h keeps animated geometry out of it,
    /// so the caller has changed what it promised not to). AccelStats: build_seconds stays the
    /// build's; bytes, nodes and references are summed again (a mesh built again may have other
    /// figures); a refit BLAS keeps its build's SAH cost.
    bool update(const SceneUpdate& update) override {
        const Scene& scene = m_scene;
        // Check everything before changing anything; duplicates and order do not matter.
        std::vector<uint8_t> deformed(scene.meshes.size(), 0), moved(scene.instances.size(), 0);
        for (uint32_t m : update.meshes) {
            if (m >= scene.meshes.size() || m_mesh_flat[m]) return false;
            deformed[m] = 1;
        }
        for (uint32_t i : update.instances) {
            if (i >= scene.instances.size() || m_flat[i]) return false;
            moved[i] = 1;
        }
        if (!update.geometry()) return true;
        // Bottom level: in parallel over the deformed meshes, on the worker pool as the build
        // (the same floating-point mode); a mesh without triangles has no BLAS to bring up to date.
        std::vector<uint32_t> meshes;
        for (uint32_t m = 0; m < deformed.size(); ++m)
            if (deformed[m] && m_blas[m]) meshes.push_back(m);
        WorkerPool(0).for_each(meshes.size(), [&](size_t k, int) {
            const Mesh& mesh = scene.meshes[meshes[k]];
            std::unique_ptr<Blas>& blas = m_blas[meshes[k]];
            if constexpr (kBlasRefits)
                blas->refit(mesh);
            else
                blas = std::make_unique<Blas>(m_build_blas(mesh));
        });
        // Top level: the moved instances' inverse transforms, then every world box (a deformed
        // mesh changes the boxes of all its instances) and a new tree over them.
        for (InstanceData& d : m_instances)
            if (d.mesh != kFlatMesh && moved[d.inst]) d = instance_data(d.inst);
        m_top = m_build_top(world_boxes());
        size_stats();
        return true;
    }

    Hit intersect(const Ray& ray, RayKind kind) const override {
        ClosestQuery<T> q(m_filter, ray, kind);
        trace(ray, q);
        return q.best;
    }

    Color transmittance(const Ray& ray) const override {
        thread_local std::vector<Crossing> scratch;
        ShadowQuery<T> q(m_filter, ray, scratch);
        trace(ray, q);
        return q.resolve([&](const Crossing& c) { return world_cosine(c, ray); });
    }

    std::string name() const override { return m_name; }
    AccelStats stats() const override { return m_stats; }

private:
    struct InstanceData {
        Affine<T> object_from_world;
        uint32_t mesh;   ///< kFlatMesh: the flat BLAS
        uint32_t inst;
        uint32_t flags;
    };
    static constexpr uint32_t kFlatMesh = kInvalidId;

    /// A triangle of the flat BLAS: where it came from.
    struct FlatPrim {
        InstanceContext ctx;  ///< its mesh, instance and filter needs
        uint32_t prim;        ///< its index in its mesh
    };

    /// The query seen by the flat BLAS: each report first takes the triangle's own context and
    /// index, so the hit or crossing names the instance, mesh and primitive it came from.
    template <class Query>
    struct FlatQuery {
        static constexpr bool kAllHits = Query::kAllHits;
        Query& q;
        const FlatPrim* prims;
        decltype(Query::tmax)& tmax;
        bool report(T t, T u, T v, uint32_t prim, uint8_t part = 0) {
            const FlatPrim& f = prims[prim];
            q.ctx = f.ctx;
            return q.report(t, u, v, f.prim, part);
        }
    };

    /// Whether Blas refits in place (else update() builds a deformed mesh's BLAS again).
    static constexpr bool kBlasRefits = requires(Blas& b, const Mesh& m) { b.refit(m); };

    /// Instance i as the top level enters it: the inverse transform (identity flagged, so the
    /// world ray's per-ray constants serve) and the filter needs of its mesh.
    InstanceData instance_data(uint32_t i) const {
        const Instance& inst = m_scene.instances[i];
        InstanceData d{Affine<T>(inst.world_from_object.inverse_affine()), inst.mesh, i,
                       m_filter.mesh_flags(inst.mesh)};
        d.object_from_world.identity = inst.world_from_object == Mat4d::identity();
        return d;
    }

    /// The world boxes of m_instances, in order: the top level is built over them.
    std::vector<Bounds3<T>> world_boxes() const {
        std::vector<Bounds3<T>> boxes;
        boxes.reserve(m_instances.size());
        for (const InstanceData& d : m_instances) {
            if (d.mesh == kFlatMesh)
                boxes.push_back(m_flat_blas->bounds());
            else
                boxes.push_back(world_box(m_blas[d.mesh]->bounds(), m_scene.instances[d.inst].world_from_object));
        }
        return boxes;
    }

    /// The size figures of m_stats (all but build_seconds): the BLASes, the top level and the
    /// per-instance data.
    void size_stats() {
        const double build_seconds = m_stats.build_seconds;
        m_stats = AccelStats{};
        m_stats.build_seconds = build_seconds;
        double sah_weighted = 0.0;
        size_t tris = 0;
        auto add = [&](const BlasStats& s, size_t triangles) {
            m_stats.bytes += s.bytes;
            m_stats.nodes += s.nodes;
            m_stats.references += s.references;
            sah_weighted += s.sah_cost * double(triangles);
            tris += triangles;
        };
        for (size_t m = 0; m < m_blas.size(); ++m)
            if (m_blas[m]) add(m_blas[m]->stats(), m_scene.meshes[m].triangle_count());
        if (m_flat_blas) add(m_flat_blas->stats(), m_flat_prims.size());
        m_stats.sah_cost = tris ? sah_weighted / double(tris) : 0.0;
        if (m_spheres) add(m_spheres->stats(), 0);  // spheres take no part in the triangles' SAH
        m_stats.bytes += m_top.bytes() + m_instances.size() * sizeof(InstanceData) + m_flat_prims.size() * sizeof(FlatPrim);
        m_stats.nodes += m_top.nodes();
    }

    /// Per instance: whether it goes into the flat BLAS (its mesh flattenable_meshes()); all 0
    /// unless at least two qualify (one alone gains nothing from sharing a BLAS).
    static std::vector<uint8_t> flattened_instances(const Scene& scene, bool flatten) {
        std::vector<uint8_t> flat(scene.instances.size(), 0);
        if (!flatten) return flat;
        size_t count = 0;
        for (int64_t i : flattenable_meshes(scene))
            if (i >= 0) flat[size_t(i)] = 1, ++count;
        if (count < 2) flat.assign(flat.size(), 0);
        return flat;
    }

    /// crossing_cosine() of a triangle crossing in world space (its vertices through the
    /// instance transform, in double); 1 for spheres, whose two roots are told apart by `part`.
    float world_cosine(const Crossing& c, const Ray& ray) const {
        if (c.inst == kInvalidId) return 1.f;
        Vec3d p[3];
        m_scene.world_triangle(c.inst, c.prim, p);
        return crossing_cosine(cross(p[1] - p[0], p[2] - p[0]), Vec3d(ray.dir));
    }

    /// World box of an object box under a transform (corners in double, rounded outwards).
    static Bounds3<T> world_box(const Bounds3<T>& object, const Mat4d& world_from_object) {
        return round_outwards<T>(transform_bounds(world_from_object, Bounds3d{Vec3d(object.lo), Vec3d(object.hi)}));
    }

    template <class Query>
    void trace(const Ray& ray, Query& q) const {
        if (!ray_is_traceable(ray)) return;
        const Vec3<T> org(ray.org), dir(ray.dir);
        const T tnear = T(ray.tnear);
        // Spheres first (world space; they set q.ctx per sphere).
        if (m_spheres && m_spheres->traverse(org, dir, tnear, q)) return;
        // Enter one instance: object-space ray, then its BLAS. A BLAS that takes the top level's
        // per-ray constants gets the world ray's when the instance's transform is the identity.
        auto visit = [&](uint32_t k, const auto& prepared) WHITTED_ALWAYS_INLINE_LAMBDA -> bool {
            const InstanceData& d = m_instances[k];
            if (d.mesh == kFlatMesh) {  // world space: the world ray's constants serve as they are
                FlatQuery<Query> fq{q, m_flat_prims.data(), q.tmax};
                if constexpr (requires { m_flat_blas->traverse_prepared(prepared, fq); })
                    return m_flat_blas->traverse_prepared(prepared, fq);
                else
                    return m_flat_blas->traverse(org, dir, tnear, fq);
            }
            q.ctx = InstanceContext{d.mesh, d.inst, d.flags};
            const Blas& blas = *m_blas[d.mesh];
            using Prepared = std::decay_t<decltype(prepared)>;
            if constexpr (requires { blas.traverse_prepared(prepared, q); }) {
                if (d.object_from_world.identity) return blas.traverse_prepared(prepared, q);
                const Prepared object(d.object_from_world.point(org), d.object_from_world.vector(dir), tnear);
                return blas.traverse_prepared(object, q);
            } else {
                if (d.object_from_world.identity) return blas.traverse(org, dir, tnear, q);
                return blas.traverse(d.object_from_world.point(org), d.object_from_world.vector(dir), tnear, q);
            }
        };
        m_top.traverse(org, dir, tnear, q, visit);
    }

    std::string m_name;
    const Scene& m_scene;  ///< outlives the accelerator (accelerator.h): triangles of crossings
    const SurfaceFilter& m_filter;
    BlasBuilder m_build_blas;                   ///< update(): meshes whose BLAS cannot refit
    TopBuilder m_build_top;                     ///< update(): the top level over the new boxes
    std::vector<uint8_t> m_flat;                ///< per instance: in the flat BLAS
    std::vector<uint8_t> m_mesh_flat;           ///< per mesh: in the flat BLAS
    std::vector<std::unique_ptr<Blas>> m_blas;  ///< per mesh; null for flattened meshes
    std::unique_ptr<Blas> m_flat_blas;         ///< the flattened meshes in world space, or null
    std::vector<FlatPrim> m_flat_prims;        ///< per triangle of m_flat_blas
    std::unique_ptr<SphereBlas> m_spheres;   ///< null when the scene has no (valid) spheres
    std::vector<InstanceData> m_instances;
    Top m_top;                               ///< over m_instances
    AccelStats m_stats;
};

}  // namespace whitted
