#include "accel/embree/embree_accel.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <cmath>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "accel/common/flatten.h"
#include "accel/common/geometry.h"
#include "accel/common/primitives.h"
#include "accel/embree/embree_ray.h"
#include "core/error.h"
#include "core/log.h"
#include "scene/scene.h"

namespace whitted {

namespace {

/// Ceiling on the bytes Embree may hold at once, all devices together (set_embree_memory_limit;
/// the CLI passes --max-memory, the importer's ceiling). Default: ImportOptions' 8 GiB.
std::atomic<size_t> g_memory_limit{size_t(8) << 30};
std::atomic<int64_t> g_memory_used{0};

/// rtcSetDeviceMemoryMonitorFunction callback: refusing an allocation (returning false) makes
/// Embree fail the build with RTC_ERROR_OUT_OF_MEMORY, reported through the error callback as
/// a whitted::Error instead of the process being killed. Frees (bytes < 0) always pass.
/// `device_bytes` (an std::atomic<int64_t>) counts what this one device holds: AccelStats::bytes.
bool memory_monitor(void* device_bytes, ssize_t bytes, bool post) {
    auto& device = *static_cast<std::atomic<int64_t>*>(device_bytes);
    if (bytes <= 0) {
        g_memory_used.fetch_add(int64_t(bytes));
        device.fetch_add(int64_t(bytes));
        return true;
    }
    const int64_t now = g_memory_used.fetch_add(int64_t(bytes)) + int64_t(bytes);
    if (!post && now > int64_t(g_memory_limit.load())) {
        g_memory_used.fetch_sub(int64_t(bytes));  // refused: Embree does not report it freed
        return false;
    }
    device.fetch_add(int64_t(bytes));
    return true;
}

/// Bytes after the last vertex: Embree reads vertices with 16-byte SSE loads, so the 12-byte
/// FLOAT3 of the last one would otherwise be read 4 bytes past the end (Embree's
/// rtcSetSharedGeometryBuffer documentation); a read outside the buffer inside Embree is
/// invisible to AddressSanitizer, so the padding is explicit rather than left to Embree. The
/// Scene's positions carry it (Mesh::positions is a PaddedVector) and are shared; the world-space
/// copies of flattened meshes get it here.
constexpr size_t kVertexPadding = 16;
static_assert(kPaddedVectorTailBytes >= kVertexPadding);

/// Surfaces remembered per shadow ray to count each crossing once. Beyond this many distinct
/// crossings de-duplication stops (the product is still taken; documented limit).
constexpr int kMaxSeen = 64;

// Two candidate hits of one (mesh, instance) within the window of same_crossing() (queries.h,
// shared with the in-house backends: kDedupUlps ulps of t, wider at grazing incidence) are one
// crossing: Embree may report a primitive twice (spatial splits) and both triangles at a shared
// edge.

struct SeenCrossing {
    uint32_t geom, inst;
    float t;
    float cosine;  ///< crossing_cosine() (1 for spheres)
    uint8_t part;  ///< which root of a sphere (0 for triangles)
};

/// What one shadow ray's crossings so far let through, and the surfaces already counted (no
/// initialiser on `seen`, so a query costs only what it uses).
struct ShadowLane {
    Color transmittance{1.f};
    int seen_count = 0;
    SeenCrossing seen[kMaxSeen];
};

/// The closest hit so far of one lane of a camera-ray query (tie rule; no default initialisers, so
/// a QueryContext costs nothing more for the other queries).
struct TieRecord {
    float t;
    uint32_t inst, geom, prim;
};

/// RTCIntersectContext extended with what our filter functions need (Embree passes the context
/// pointer through; it must be the first member).
struct QueryContext {
    RTCIntersectContext rtc;
    const SurfaceFilter* filter = nullptr;
    const std::vector<uint32_t>* mesh_of_instance = nullptr;
    /// The world-space rays as the caller gave them: one for a single-ray query, a packet's for a
    /// batch. Callbacks find a lane's ray by the RTCRay id (its index here), which Embree keeps
    /// even where it reorders the rays of a packet.
    const Ray* rays = nullptr;
    RayKind kind = RayKind::Camera;
    /// Camera rays: per lane (RTCRay id), the hit accepted so far, for the tie rule
    /// (camera_tie_filter); set by context() for camera queries only (t = inf: none yet), left
    /// uninitialised for the others (no cost to shadow rays).
    TieRecord best[16];
    /// Shadow queries: per lane (RTCRay id), what the crossings so far let through; null for
    /// closest-hit queries.
    ShadowLane* shadow = nullptr;
};

Hit hit_from_filter_args(const RTCFilterFunctionNArguments* args, unsigned i, const QueryContext& q) {
    Hit h;
    h.t = RTCRayN_tfar(args->ray, args->N, i);
    h.u = RTCHitN_u(args->hit, args->N, i);
    h.v = RTCHitN_v(args->hit, args->N, i);
    h.prim = RTCHitN_primID(args->hit, args->N, i);
    h.inst = RTCHitN_instID(args->hit, args->N, i, 0);
    // A flattened mesh sits in the top-level scene, its geometry ID the instance's index.
    if (h.inst == RTC_INVALID_GEOMETRY_ID) h.inst = RTCHitN_geomID(args->hit, args->N, i);
    h.geom = (*q.mesh_of_instance)[h.inst];
    return h;
}

/// Closest-hit filter: alpha-mask cut-outs and camera-ray back-face culling.
void intersect_filter(const RTCFilterFunctionNArguments* args) {
    const auto& q = *reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const Hit h = hit_from_filter_args(args, i, q);
        if (!q.filter->accept(q.rays[RTCRayN_id(args->ray, args->N, i)], h, q.kind)) args->valid[i] = 0;
    }
}

/// The tie rule of every closest-hit query (tie_precedes, queries.h): a candidate at exactly the t
/// of the lane's best hit wins only with smaller (instance, geometry, primitive) ids.
bool loses_tie(const Hit& h, const TieRecord& best) {
    if (h.t != best.t) return false;
    Hit b;
    b.inst = best.inst;
    b.geom = best.geom;
    b.prim = best.prim;
    return !tie_precedes(h, b);
}

void record(TieRecord& best, const Hit& h) { best = {h.t, h.inst, h.geom, h.prim}; }

/// Context filter of camera-ray queries (after the geometry's own filter): the tie rule. Embree
/// offers every candidate with t <= tfar, and which of two at the same t it meets last differs
/// between its packet and single-ray traversals; camera rays are the only rays the kernels trace
/// both ways (the specialised ones in packets, the general one ray by ray), so with the rule the
/// kernels' images agree bit for bit. Secondary rays, always single, need no callback.
void camera_tie_filter(const RTCFilterFunctionNArguments* args) {
    auto& q = *reinterpret_cast<QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const Hit h = hit_from_filter_args(args, i, q);
        TieRecord& best = q.best[RTCRayN_id(args->ray, args->N, i)];
        if (loses_tie(h, best)) args->valid[i] = 0;
        else record(best, h);
    }
}

/// One candidate crossing of a shadow ray, in traversal order, with crossing_cosine() `cosine`:
/// multiplies its transmittance unless the same surface was already counted (per (geom, inst,
/// part) within the same_crossing() window). Returns true once nothing passes any more.
bool add_crossing(const QueryContext& q, unsigned lane, const Hit& h, uint8_t part, float cosine) {
    ShadowLane& l = q.shadow[lane];
    for (int k = 0; k < l.seen_count; ++k) {
        const SeenCrossing& s = l.seen[k];
        if (s.geom == h.geom && s.inst == h.inst && s.part == part && same_crossing(s.t, s.cosine, h.t, cosine))
            return false;
    }
    const Color tr = q.filter->transmittance(q.rays[lane], h);
    if (l.seen_count < kMaxSeen) l.seen[l.seen_count++] = {h.geom, h.inst, h.t, cosine, part};
    l.transmittance *= tr;
    if (!is_black(l.transmittance)) return false;
    l.transmittance = Color(0.f);
    return true;
}

/// Shadow filter: multiplies the transmittance of each distinct crossing and rejects the hit
/// so traversal continues; accepts (terminating the query) once nothing passes.
void occluded_filter(const RTCFilterFunctionNArguments* args) {
    auto& q = *reinterpret_cast<QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        // The incidence, from Embree's geometric normal and the ray as the filter sees it (both
        // in the instance's object space, where t was computed).
        const Vec3f ng{RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                       RTCHitN_Ng_z(args->hit, args->N, i)};
        const Vec3f dir{RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                        RTCRayN_dir_z(args->ray, args->N, i)};
        // Keep the hit (the ray is blocked, traversal stops) only once nothing passes.
        const unsigned lane = RTCRayN_id(args->ray, args->N, i);
        if (!add_crossing(q, lane, hit_from_filter_args(args, i, q), 0, crossing_cosine(ng, dir))) args->valid[i] = 0;
    }
}

// ---------------------------------------------------------------------------------------------
// The scene's spheres and quadrics as one RTC_GEOMETRY_TYPE_USER geometry in the top-level scene
// (primitive i = AnalyticPrims item i). Embree runs no filter functions for user geometry, so the callbacks
// apply the same rules as the triangle filters above: accept() for kNeedsAccept, and for shadow
// rays add_crossing() for both crossings with kNeedsTransmittance, else blocked at once. The
// crossings come from the in-house kernels (sphere_roots<float>, quadric_crossings), so t is the
// float `bvh` backend's t.

Hit analytic_hit(const AnalyticPrims<float>::Item& s, float t, uint32_t face) {
    Hit h;
    h.t = t;
    h.prim = face;
    h.geom = s.geom;
    h.inst = kInvalidId;
    return h;
}

void analytic_bounds_fn(const RTCBoundsFunctionArguments* args) {
    const auto& spheres = *static_cast<const AnalyticPrims<float>*>(args->geometryUserPtr);
    const Bounds3f b = spheres.bounds(args->primID);
    args->bounds_o->lower_x = b.lo.x;
    args->bounds_o->lower_y = b.lo.y;
    args->bounds_o->lower_z = b.lo.z;
    args->bounds_o->upper_x = b.hi.x;
    args->bounds_o->upper_y = b.hi.y;
    args->bounds_o->upper_z = b.hi.z;
}

/// The crossings of ray i of a ray packet with item `s` (AnalyticPrims::crossings).
template <bool kQuadric>
int packet_crossings(const AnalyticPrims<float>& prims, RTCRayN* ray, unsigned n, unsigned i,
                     const AnalyticPrims<float>::Item& s, float t[2], uint8_t face[2]) {
    const Vec3f org{RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i)};
    const Vec3f dir{RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i)};
    return prims.crossings<kQuadric>(s, org, dir, t, face);
}

/// Closest hit: the nearer crossing in (tnear, tfar] that accept() takes, else the farther one.
template <bool kQuadric>
void analytic_intersect(const RTCIntersectFunctionNArguments* args, const AnalyticPrims<float>& prims,
                        const AnalyticPrims<float>::Item& s) {
    auto& q = *reinterpret_cast<QueryContext*>(args->context);
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        float roots[2];
        uint8_t face[2];
        const int n = packet_crossings<kQuadric>(prims, ray, args->N, i, s, roots, face);
        const float tnear = RTCRayN_tnear(ray, args->N, i);
        float& tfar = RTCRayN_tfar(ray, args->N, i);
        const unsigned lane = RTCRayN_id(ray, args->N, i);
        for (int r = 0; r < n; ++r) {
            const float t = roots[r];
            if (!(t > tnear && t <= tfar)) continue;
            const Hit h = analytic_hit(s, t, face[r]);
            if ((s.flags & SurfaceFilter::kNeedsAccept) && !q.filter->accept(q.rays[lane], h, q.kind)) continue;
            if (q.kind == RayKind::Camera) {  // camera_tie_filter's rule (no filter runs for user geometry)
                if (loses_tie(h, q.best[lane])) continue;
                record(q.best[lane], h);
            }
            tfar = t;
            RTCHitN_u(hit, args->N, i) = float(face[r]);  // the face crossed (to_hit: Hit::prim)
            RTCHitN_v(hit, args->N, i) = 0.f;
            // Embree's geometric normal (which whitted does not read): a sphere's outward
            // direction; for a quadric, against the ray (SceneView computes its normal).
            if constexpr (kQuadric) {
                RTCHitN_Ng_x(hit, args->N, i) = -RTCRayN_dir_x(ray, args->N, i);
                RTCHitN_Ng_y(hit, args->N, i) = -RTCRayN_dir_y(ray, args->N, i);
                RTCHitN_Ng_z(hit, args->N, i) = -RTCRayN_dir_z(ray, args->N, i);
            } else {
                RTCHitN_Ng_x(hit, args->N, i) = RTCRayN_org_x(ray, args->N, i) + t * RTCRayN_dir_x(ray, args->N, i) - float(s.center.x);
                RTCHitN_Ng_y(hit, args->N, i) = RTCRayN_org_y(ray, args->N, i) + t * RTCRayN_dir_y(ray, args->N, i) - float(s.center.y);
                RTCHitN_Ng_z(hit, args->N, i) = RTCRayN_org_z(ray, args->N, i) + t * RTCRayN_dir_z(ray, args->N, i) - float(s.center.z);
            }
            RTCHitN_primID(hit, args->N, i) = args->primID;
            RTCHitN_geomID(hit, args->N, i) = args->geomID;
            RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
            break;
        }
    }
}

void analytic_intersect_fn(const RTCIntersectFunctionNArguments* args) {
    const auto& prims = *static_cast<const AnalyticPrims<float>*>(args->geometryUserPtr);
    const AnalyticPrims<float>::Item& s = prims.item(args->primID);
    if (prims.is_quadric(s)) analytic_intersect<true>(args, prims, s);
    else analytic_intersect<false>(args, prims, s);
}

/// Shadow rays: every crossing in (tnear, tfar] counts (in and out).
template <bool kQuadric>
void analytic_occluded(const RTCOccludedFunctionNArguments* args, const AnalyticPrims<float>& prims,
                       const AnalyticPrims<float>::Item& s) {
    auto& q = *reinterpret_cast<QueryContext*>(args->context);
    const bool opaque = !(s.flags & SurfaceFilter::kNeedsTransmittance);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        float roots[2];
        uint8_t face[2];
        const int n = packet_crossings<kQuadric>(prims, args->ray, args->N, i, s, roots, face);
        const float tnear = RTCRayN_tnear(args->ray, args->N, i);
        float& tfar = RTCRayN_tfar(args->ray, args->N, i);
        for (int part = 0; part < n; ++part) {
            const float t = roots[part];
            if (!(t > tnear && t <= tfar)) continue;
            if (opaque || add_crossing(q, RTCRayN_id(args->ray, args->N, i), analytic_hit(s, t, face[part]),
                                       uint8_t(part), 1.f)) {
                tfar = -kInfinity;  // Embree's mark for an occluded ray
                break;
            }
        }
    }
}

void analytic_occluded_fn(const RTCOccludedFunctionNArguments* args) {
    const auto& prims = *static_cast<const AnalyticPrims<float>*>(args->geometryUserPtr);
    const AnalyticPrims<float>::Item& s = prims.item(args->primID);
    if (prims.is_quadric(s)) analytic_occluded<true>(args, prims, s);
    else analytic_occluded<false>(args, prims, s);
}

/// rtcIntersect4/8/16 and their ray-hit structures by width.
template <int K>
struct EmbreePacket;
template <>
struct EmbreePacket<4> {
    using RayHit = RTCRayHit4;
    using Ray = RTCRay4;
    static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect4(valid, s, c, rh); }
    static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded4(valid, s, c, r); }
};
template <>
struct EmbreePacket<8> {
    using RayHit = RTCRayHit8;
    using Ray = RTCRay8;
    static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect8(valid, s, c, rh); }
    static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded8(valid, s, c, r); }
};
template <>
struct EmbreePacket<16> {
    using RayHit = RTCRayHit16;
    using Ray = RTCRay16;
    static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect16(valid, s, c, rh); }
    static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded16(valid, s, c, r); }
};

class EmbreeAccelerator final : public Accelerator {
public:
    using Accelerator::intersect;
    using Accelerator::transmittance;

    EmbreeAccelerator(const Scene& scene, const SurfaceFilter& filter, const EmbreeConfig& config)
        : m_scene(scene), m_filter(filter), m_packet_width(config.packet_width),
          m_shadow_packet_width(config.shadow_packet_width), m_compact(config.compact) {
        auto start = std::chrono::steady_clock::now();
        std::string device_config = config.threads > 0 ? "threads=" + std::to_string(config.threads) : "";
        m_device = rtcNewDevice(device_config.c_str());
        if (!m_device) throw Error(fmt::format("Embree: cannot create device ({})", int(rtcGetDeviceError(nullptr))));
        rtcSetDeviceErrorFunction(m_device, &EmbreeAccelerator::on_error, this);
        rtcSetDeviceMemoryMonitorFunction(m_device, &memory_monitor, &m_device_bytes);

        // Context filters (camera_tie_filter) must be enabled in every scene, instanced ones too.
        const RTCSceneFlags flags = RTCSceneFlags((config.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE) |
                                                  (config.compact ? RTC_SCENE_FLAG_COMPACT : RTC_SCENE_FLAG_NONE) |
                                                  RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);

        // Which meshes are flattened (common/flatten.h): per mesh, the instance that places it.
        const std::vector<int64_t> flat_instance =
            config.flatten ? flattenable_meshes(scene) : std::vector<int64_t>(scene.meshes.size(), -1);

        // One Embree scene per instanced mesh (geometry ID 0 inside it); flattened meshes are
        // built in world space and attached to the top level below.
        m_top = rtcNewScene(m_device);
        m_mesh_scenes.assign(scene.meshes.size(), nullptr);
        for (size_t m = 0; m < scene.meshes.size(); ++m) {
            const Mesh& mesh = scene.meshes[m];
            if (mesh.triangle_count() == 0) continue;
            const Mat4d* to_world = flat_instance[m] >= 0 ? &scene.instances[size_t(flat_instance[m])].world_from_object : nullptr;
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
            // Vertices: the Scene's own array, shared (its allocation is padded, scene.h), or for a
            // flattened mesh a world-space copy with the same padding, zero-filled.
            float* v = nullptr;
            if (to_world) {
                const size_t vertex_bytes = mesh.positions.size() * 3 * sizeof(float);
                RTCBuffer vb = rtcNewBuffer(m_device, vertex_bytes + kVertexPadding);
                v = vb ? static_cast<float*>(rtcGetBufferData(vb)) : nullptr;
                if (v) {
                    std::memset(reinterpret_cast<char*>(v) + vertex_bytes, 0, kVertexPadding);
                    rtcSetGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 0, 3 * sizeof(float),
                                         mesh.positions.size());
                }
                if (vb) rtcReleaseBuffer(vb);  // the geometry holds its own reference
                if (!v) {
                    rtcReleaseGeometry(g);
                    throw_pending("allocating geometry buffers");
                    throw Error("Embree: cannot allocate geometry buffers");
                }
                for (size_t i = 0; i < mesh.positions.size(); ++i) {
                    const Vec3f p(to_world->apply_point(Vec3d(mesh.positions[i])));  // double, rounded once
                    v[3 * i + 0] = p.x;
                    v[3 * i + 1] = p.y;
                    v[3 * i + 2] = p.z;
                }
            } else {
                static_assert(sizeof(Vec3f) == 3 * sizeof(float));
                rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0,
                                           sizeof(Vec3f), mesh.positions.size());
            }
            // The index buffer is the Scene's own array, shared too: Embree reads indices one by one
            // (the 16-byte-load padding rule is for vertex buffers). The Scene outlives the
            // accelerator (accelerator.h).
            rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0,
                                       3 * sizeof(uint32_t), mesh.triangle_count());
            // A deforming mesh's BVH is refit when its vertices move (update()); its own scene,
            // never flattened (common/flatten.h).
            if (mesh.deforming) rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT);
            const uint32_t needs = filter.mesh_flags(uint32_t(m));
            if (needs & SurfaceFilter::kNeedsAccept) rtcSetGeometryIntersectFilterFunction(g, &intersect_filter);
            // Shadow rays read kNeedsTransmittance only (accelerator.h): an opaque single-sided
            // mesh gets a filter-free rtcOccluded.
            if (needs & SurfaceFilter::kNeedsTransmittance) rtcSetGeometryOccludedFilterFunction(g, &occluded_filter);
            rtcCommitGeometry(g);
            if (to_world) {
                rtcAttachGeometryByID(m_top, g, unsigned(flat_instance[m]));  // geometry ID = instance index
                rtcReleaseGeometry(g);
                ++m_flattened;
                continue;
            }
            RTCScene s = rtcNewScene(m_device);
            // Embree reads a geometry's REFIT quality only in a DYNAMIC scene of LOW quality (its
            // two-level build; rtcSetGeometryBuildQuality(3)): otherwise update() rebuilds the mesh
            // (1M triangles: 125 ms a commit, against 8 ms refitted; docs/performance.md).
            rtcSetSceneBuildQuality(s, mesh.deforming ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
            rtcSetSceneFlags(s, mesh.deforming ? RTCSceneFlags(flags | RTC_SCENE_FLAG_DYNAMIC) : flags);
            rtcAttachGeometryByID(s, g, 0);
            rtcReleaseGeometry(g);
            rtcCommitScene(s);
            m_mesh_scenes[m] = s;
        }

        // The top level: one instance per Instance, geometry ID = instance index (a flattened
        // mesh's triangles already hold that ID).
        rtcSetSceneBuildQuality(m_top, RTC_BUILD_QUALITY_MEDIUM);
        rtcSetSceneFlags(m_top, flags);
        m_mesh_of_instance.resize(scene.instances.size());
        for (size_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& inst = scene.instances[i];
            m_mesh_of_instance[i] = inst.mesh;
            RTCScene child = inst.mesh < m_mesh_scenes.size() ? m_mesh_scenes[inst.mesh] : nullptr;
            if (!child) continue;  // empty or flattened
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, child);
            set_transform(g, inst.world_from_object);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m_top, g, unsigned(i));
            rtcReleaseGeometry(g);
        }
        // The spheres and quadrics: one user geometry with its own callbacks, geometry ID after the instances.
        m_analytic = AnalyticPrims<float>(scene, filter);
        if (m_analytic.size() > 0) {
            m_analytic_geom_id = unsigned(scene.instances.size());
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, m_analytic.size());
            rtcSetGeometryUserData(g, &m_analytic);
            rtcSetGeometryBoundsFunction(g, &analytic_bounds_fn, nullptr);
            rtcSetGeometryIntersectFunction(g, &analytic_intersect_fn);
            rtcSetGeometryOccludedFunction(g, &analytic_occluded_fn);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m_top, g, m_analytic_geom_id);
            rtcReleaseGeometry(g);
            m_analytic_bytes = m_analytic.bytes();
        }
        rtcCommitScene(m_top);
        throw_pending("building the scene");
        m_build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    ~EmbreeAccelerator() override {
        if (m_top) rtcReleaseScene(m_top);
        for (RTCScene s : m_mesh_scenes)
            if (s) rtcReleaseScene(s);
        if (m_device) rtcReleaseDevice(m_device);
    }

    Hit intersect(const Ray& ray, RayKind kind) const override {
        if (!ray_is_traceable(ray)) return Hit{};  // NaN/zero-direction rays: Embree asserts on them
        if (m_compact) {
            // Compact leaves (Triangle4i) get a different single-ray kernel than packets on some
            // ISAs (seen on AVX2: 2-6 % of rays missed or hit differently than rtcIntersect4/8/16
            // and the default leaves, docs/accelerators.md); a one-lane packet takes the same
            // kernel as every batch.
            Hit h;
            intersect_packets<4>(std::span<const Ray>(&ray, 1), kind, std::span<Hit>(&h, 1));
            return h;
        }
        QueryContext q = context(&ray, kind);
        RTCRayHit rh;
        set_rtc_ray(rh.ray, ray);  // id 0: q.rays[0]
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_top, &q.rtc, &rh);
        return to_hit(rh.hit.geomID, rh.hit.instID[0], rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v);
    }

    /// Packets of m_packet_width consecutive rays (rtcIntersect4/8/16, coherent context); a
    /// partial last packet and untraceable rays are masked-off lanes.
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        RT_CHECK_EQ(rays.size(), hits.size());
        switch (m_packet_width) {
            case 4: return intersect_packets<4>(rays, kind, hits);
            case 8: return intersect_packets<8>(rays, kind, hits);
            case 16: return intersect_packets<16>(rays, kind, hits);
            default: Accelerator::intersect(rays, kind, hits);
        }
    }

    Color transmittance(const Ray& ray) const override {
        if (!ray_is_traceable(ray)) return Color(1.f);
        QueryContext q = context(&ray, RayKind::Shadow);
        ShadowLane lane;
        q.shadow = &lane;
        RTCRay r;
        set_rtc_ray(r, ray);
        rtcOccluded1(m_top, &q.rtc, &r);
        if (r.tfar == -kInfinity) return Color(0.f);  // an opaque surface blocked it
        return lane.transmittance;
    }

    /// Packets of m_shadow_packet_width consecutive shadow rays (rtcOccluded4/8/16), each lane
    /// with its own crossings; a partial last packet and untraceable rays are masked-off lanes
    /// (untraceable ones let everything through, as one by one). 4 and 8 lanes run with the
    /// coherent context, 16 with the incoherent one: Debian's Embree 3.13 never returned from a
    /// coherent rtcOccluded16 on two of AccelBatch's reflection rays (an AVX-512 machine), and
    /// incoherent 16-wide packets answer all 52,326 of them as single rays do.
    void transmittance(std::span<const Ray> rays, std::span<Color> out) const override {
        RT_CHECK_EQ(rays.size(), out.size());
        switch (m_shadow_packet_width) {
            case 4: return occluded_packets<4>(rays, out);
            case 8: return occluded_packets<8>(rays, out);
            case 16: return occluded_packets<16>(rays, out);
            default: Accelerator::transmittance(rays, out);
        }
    }

    std::string name() const override { return "embree"; }
    /// bytes: what the device's memory monitor counts once the build is done (BVHs, the
    /// world-space vertex copies of flattened meshes, Embree's internal buffers), plus the sphere
    /// table; the shared vertex and index arrays belong to the Scene and are not counted.
    AccelStats stats() const override {
        return {m_build_seconds, size_t(std::max<int64_t>(m_device_bytes.load(), 0)) + m_analytic_bytes};
    }

private:
    QueryContext context(const Ray* rays, RayKind kind) const {
        QueryContext q;
        rtcInitIntersectContext(&q.rtc);
        q.filter = &m_filter;
        q.mesh_of_instance = &m_mesh_of_instance;
        q.rays = rays;
        q.kind = kind;
        if (kind == RayKind::Camera) {
            q.rtc.filter = &camera_tie_filter;
            for (TieRecord& b : q.best) b.t = kInfinity;
        }
        return q;
    }

    /// Our hit record from Embree's (one ray or one packet lane).
    Hit to_hit(unsigned geom_id, unsigned inst_id, unsigned prim_id, float t, float u, float v) const {
        Hit h;
        if (geom_id == RTC_INVALID_GEOMETRY_ID) return h;
        if (geom_id == m_analytic_geom_id) return analytic_hit(m_analytic.item(prim_id), t, uint32_t(u));
        h.t = t;
        h.u = u;
        h.v = v;
        h.prim = prim_id;
        h.inst = inst_id != RTC_INVALID_GEOMETRY_ID ? inst_id : geom_id;  // flattened: geometry ID = instance
        h.geom = m_mesh_of_instance[h.inst];
        return h;
    }

    /// Lanes of a packet from up to K rays: each lane's ray id is its index (q.rays, q.shadow);
    /// lanes past the rays and untraceable rays are masked off (valid 0) but still hold a finite
    /// ray, since Embree loads whole packets. Returns whether any lane is on.
    template <int K, class RTCRayK>
    static bool fill_lanes(RTCRayK& r, int* valid, std::span<const Ray> rays) {
        const Ray off{Vec3f(0.f), Vec3f(0.f, 0.f, 1.f), 0.f, 0.f};
        bool any = false;
        for (int i = 0; i < K; ++i) {
            const bool on = size_t(i) < rays.size() && ray_is_traceable(rays[size_t(i)]);
            valid[i] = on ? -1 : 0;
            any |= on;
            set_rtc_lane(r, i, on ? rays[size_t(i)] : off);
            r.id[i] = unsigned(i);
        }
        return any;
    }

    template <int K>
    void intersect_packets(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const {
        using Packet = typename EmbreePacket<K>::RayHit;
        for (size_t base = 0; base < rays.size(); base += K) {
            const size_t n = std::min(rays.size() - base, size_t(K));
            QueryContext q = context(rays.data() + base, kind);
            q.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            alignas(64) int valid[K];
            Packet rh;
            const bool any = fill_lanes<K>(rh.ray, valid, rays.subspan(base, n));
            for (int i = 0; i < K; ++i) {
                rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            if (any) EmbreePacket<K>::intersect(valid, m_top, &q.rtc, &rh);
            for (size_t i = 0; i < n; ++i)
                hits[base + i] = valid[i] ? to_hit(rh.hit.geomID[i], rh.hit.instID[0][i], rh.hit.primID[i],
                                                   rh.ray.tfar[i], rh.hit.u[i], rh.hit.v[i])
                                          : Hit{};
        }
    }

    template <int K>
    void occluded_packets(std::span<const Ray> rays, std::span<Color> out) const {
        using Packet = typename EmbreePacket<K>::Ray;
        for (size_t base = 0; base < rays.size(); base += K) {
            const size_t n = std::min(rays.size() - base, size_t(K));
            QueryContext q = context(rays.data() + base, RayKind::Shadow);
            q.rtc.flags = K == 16 ? RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT : RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            ShadowLane lanes[K];
            q.shadow = lanes;
            alignas(64) int valid[K];
            Packet r;
            const bool any = fill_lanes<K>(r, valid, rays.subspan(base, n));
            if (any) EmbreePacket<K>::occluded(valid, m_top, &q.rtc, &r);
            for (size_t i = 0; i < n; ++i)
                out[base + i] = !valid[i] ? Color(1.f) : r.tfar[i] == -kInfinity ? Color(0.f) : lanes[i].transmittance;
        }
    }

    /// Deformed meshes: their shared vertex buffers (rewritten in place) refit; moved instances and
    /// those of the deformed meshes: their transforms set again; then the top level is committed.
    /// False (rebuild) for anything not built to change: a flattened or empty mesh, an instance
    /// without its own scene, a vertex array that was reallocated.
    bool update(const SceneUpdate& u) override {
        for (uint32_t m : u.meshes)
            if (m >= m_mesh_scenes.size() || !m_mesh_scenes[m] || !m_scene.meshes[m].deforming ||
                rtcGetGeometryBufferData(rtcGetGeometry(m_mesh_scenes[m], 0), RTC_BUFFER_TYPE_VERTEX, 0) !=
                    m_scene.meshes[m].positions.data())
                return false;
        for (uint32_t i : u.instances)
            if (i >= m_mesh_of_instance.size() || m_mesh_of_instance[i] >= m_mesh_scenes.size() ||
                !m_mesh_scenes[m_mesh_of_instance[i]])
                return false;
        for (uint32_t m : u.meshes) {
            RTCGeometry g = rtcGetGeometry(m_mesh_scenes[m], 0);
            rtcUpdateGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0);
            rtcCommitGeometry(g);
            rtcCommitScene(m_mesh_scenes[m]);
        }
        // Every instance of a changed mesh is committed again (its bounds moved), moved ones with
        // their new transform.
        std::vector<uint8_t> changed(m_mesh_scenes.size(), 0);
        for (uint32_t m : u.meshes) changed[m] = 1;
        std::vector<uint8_t> moved(m_mesh_of_instance.size(), 0);
        for (uint32_t i : u.instances) moved[i] = 1;
        for (size_t i = 0; i < m_mesh_of_instance.size(); ++i) {
            const uint32_t m = m_mesh_of_instance[i];
            if (!moved[i] && !(m < changed.size() && changed[m] && m_mesh_scenes[m])) continue;
            RTCGeometry g = rtcGetGeometry(m_top, unsigned(i));
            if (moved[i]) set_transform(g, m_scene.instances[i].world_from_object);
            rtcCommitGeometry(g);
        }
        rtcCommitScene(m_top);
        throw_pending("updating the scene");
        return true;
    }

    static void set_transform(RTCGeometry g, const Mat4d& world_from_object) {
        float xfm[12];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) xfm[r * 4 + c] = float(world_from_object(r, c));
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
    }

    static void on_error(void* user, RTCError code, const char* message) {
        auto* self = static_cast<EmbreeAccelerator*>(user);
        std::lock_guard lock(self->m_error_mutex);
        if (!self->m_error.empty()) return;
        self->m_error = fmt::format("Embree error {}: {}", int(code), message ? message : "");
        if (code == RTC_ERROR_OUT_OF_MEMORY)
            self->m_error +=
                fmt::format(" (Embree's memory ceiling is {} MiB: --max-memory)", g_memory_limit.load() >> 20);
    }

    void throw_pending(const char* what) {
        std::lock_guard lock(m_error_mutex);
        if (!m_error.empty()) throw Error(fmt::format("{} while {}", m_error, what));
    }

    const Scene& m_scene;  ///< outlives the accelerator (accelerator.h): update() reads its changes
    const SurfaceFilter& m_filter;
    RTCDevice m_device = nullptr;
    RTCScene m_top = nullptr;
    std::vector<RTCScene> m_mesh_scenes;
    std::vector<uint32_t> m_mesh_of_instance;
    size_t m_flattened = 0;  ///< meshes placed in the top level in world space (EmbreeConfig::flatten)
    AnalyticPrims<float> m_analytic;                         ///< user data of the sphere geometry
    unsigned m_analytic_geom_id = RTC_INVALID_GEOMETRY_ID;  ///< its geometry ID in m_top
    std::mutex m_error_mutex;
    std::string m_error;
    double m_build_seconds = 0.0;
    std::atomic<int64_t> m_device_bytes{0};  ///< the memory monitor's count for m_device
    size_t m_analytic_bytes = 0;               ///< AnalyticPrims, ours (user data)
    int m_packet_width = 4;   ///< EmbreeConfig::packet_width
    int m_shadow_packet_width = 16;  ///< EmbreeConfig::shadow_packet_width
    bool m_compact = false;   ///< EmbreeConfig::compact: single rays go through one-lane packets
};

}  // namespace

void set_embree_memory_limit(size_t bytes) { g_memory_limit.store(bytes); }

std::unique_ptr<Accelerator> create_embree_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                       const EmbreeConfig& config) {
    return std::make_unique<EmbreeAccelerator>(scene, filter, config);
}

}  // namespace whitted
