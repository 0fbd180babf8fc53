#include "renderer/accel/embree/embree_accel.h"

#include <embree3/rtcore.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "renderer/accel/common/geometry.h"
#include "renderer/core/error.h"
#include "renderer/core/log.h"
#include "renderer/scene/scene.h"

namespace whitted {

namespace {

/// Ceiling on the bytes Embree may hold at once, all devices together (set_embree_memory_limit;
/// the CLI passes --max-memory, the importer's ceiling). Default: ImportOptions' 8 GiB.
std::atomic<size_t> g_memory_limit{size_t(8) << 30};
std::atomic<int64_t> g_memory_used{0};

/// rtcSetDeviceMemoryMonitorFunction callback: refusing an allocation (returning false) makes
/// Embree fail the build with RTC_ERROR_OUT_OF_MEMORY, reported through the error callback as
/// a whitted::Error instead of the process being killed. Frees (bytes < 0) always pass.
bool memory_monitor(void*, ssize_t bytes, bool post) {
    if (bytes <= 0) {
        g_memory_used.fetch_add(int64_t(bytes));
        return true;
    }
    const int64_t now = g_memory_used.fetch_add(int64_t(bytes)) + int64_t(bytes);
    if (!post && now > int64_t(g_memory_limit.load())) {
        g_memory_used.fetch_sub(int64_t(bytes));  // refused: Embree does not report it freed
        return false;
    }
    return true;
}

/// Bytes after the last vertex: Embree reads vertices with 16-byte SSE loads, so the 12-byte
/// FLOAT3 of the last one would otherwise be read 4 bytes past the end (Embree's
/// rtcSetSharedGeometryBuffer documentation); a read outside the buffer inside Embree is
/// invisible to AddressSanitizer, so the padding is explicit rather than left to Embree.
constexpr size_t kVertexPadding = 16;

/// Surfaces remembered per shadow ray to count each crossing once. Beyond this many distinct
/// crossings de-duplication stops (the product is still taken; documented limit).
constexpr int kMaxSeen = 64;

/// Two candidate hits of one (mesh, instance) closer than this many ulps of t are one crossing:
/// Embree may report a primitive twice (spatial splits) and both triangles at a shared edge.
constexpr float kDedupUlps = 64.f;

struct SeenCrossing {
    uint32_t geom, inst;
    float t;
};

/// RTCIntersectContext extended with what our filter functions need (Embree passes the context
/// pointer through; it must be the first member).
struct QueryContext {
    RTCIntersectContext rtc;
    const SurfaceFilter* filter = nullptr;
    const std::vector<uint32_t>* mesh_of_instance = nullptr;
    const Ray* ray = nullptr;           ///< the world-space ray as the caller gave it
    RayKind kind = RayKind::Camera;
    Color transmittance{1.f};
    int seen_count = 0;
    SeenCrossing seen[kMaxSeen];
};

Hit hit_from_filter_args(const RTCFilterFunctionNArguments* args, unsigned i, const QueryContext& q) {
    Hit h;
    h.t = RTCRayN_tfar(args->ray, args->N, i);
    h.u = RTCHitN_u(args->hit, args->N, i);
    h.v = RTCHitN_v(args->hit, args->N, i);
    h.prim = RTCHitN_primID(args->hit, args->N, i);
    h.inst = RTCHitN_instID(args->hit, args->N, i, 0);
    h.geom = (*q.mesh_of_instance)[h.inst];
    return h;
}

/// Closest-hit filter: alpha-mask cut-outs and camera-ray back-face culling.
void intersect_filter(const RTCFilterFunctionNArguments* args) {
    const auto& q = *reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        Hit h = hit_from_filter_args(args, i, q);
        if (!q.filter->accept(*q.ray, h, q.kind)) args->valid[i] = 0;
    }
}

/// Shadow filter: multiplies the transmittance of each distinct crossing and rejects the hit
/// so traversal continues; accepts (terminating the query) once nothing passes.
void occluded_filter(const RTCFilterFunctionNArguments* args) {
    auto& q = *reinterpret_cast<QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        Hit h = hit_from_filter_args(args, i, q);
        // Count each surface crossing once.
        float window = kDedupUlps * (std::nextafter(std::fabs(h.t), kInfinity) - std::fabs(h.t));
        bool duplicate = false;
        for (int k = 0; k < q.seen_count; ++k) {
            const SeenCrossing& s = q.seen[k];
            if (s.geom == h.geom && s.inst == h.inst && std::fabs(s.t - h.t) <= window) {
                duplicate = true;
                break;
            }
        }
        if (duplicate) {
            args->valid[i] = 0;
            continue;
        }
        Color tr = q.filter->transmittance(*q.ray, h);
        if (q.seen_count < kMaxSeen) q.seen[q.seen_count++] = {h.geom, h.inst, h.t};
        q.transmittance *= tr;
        if (is_black(q.transmittance)) {
            q.transmittance = Color(0.f);
            continue;  // keep the hit: the ray is blocked, traversal stops
        }
        args->valid[i] = 0;
    }
}

class EmbreeAccelerator final : public Accelerator {
public:
    EmbreeAccelerator(const Scene& scene, const SurfaceFilter& filter, const EmbreeConfig& config)
        : m_filter(filter) {
        auto start = std::chrono::steady_clock::now();
        std::string device_config = config.threads > 0 ? "threads=" + std::to_string(config.threads) : "";
        m_device = rtcNewDevice(device_config.c_str());
        if (!m_device) throw Error(fmt::format("Embree: cannot create device ({})", int(rtcGetDeviceError(nullptr))));
        rtcSetDeviceErrorFunction(m_device, &EmbreeAccelerator::on_error, this);
        rtcSetDeviceMemoryMonitorFunction(m_device, &memory_monitor, nullptr);

        const RTCSceneFlags flags = config.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE;

        // One Embree scene per mesh, geometry ID 0 inside it.
        m_mesh_scenes.assign(scene.meshes.size(), nullptr);
        for (size_t m = 0; m < scene.meshes.size(); ++m) {
            const Mesh& mesh = scene.meshes[m];
            if (mesh.triangle_count() == 0) continue;
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
            // Vertex buffer with explicit tail padding (kVertexPadding), zero-filled.
            const size_t vertex_bytes = mesh.positions.size() * 3 * sizeof(float);
            RTCBuffer vb = rtcNewBuffer(m_device, vertex_bytes + kVertexPadding);
            auto* v = vb ? static_cast<float*>(rtcGetBufferData(vb)) : nullptr;
            if (v) {
                std::memset(reinterpret_cast<char*>(v) + vertex_bytes, 0, kVertexPadding);
                rtcSetGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 0, 3 * sizeof(float),
                                     mesh.positions.size());
            }
            if (vb) rtcReleaseBuffer(vb);  // the geometry holds its own reference
            auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(uint32_t), mesh.triangle_count()));
            if (!v || !idx) {
                rtcReleaseGeometry(g);
                throw_pending("allocating geometry buffers");
                throw Error("Embree: cannot allocate geometry buffers");
            }
            for (size_t i = 0; i < mesh.positions.size(); ++i) {
                v[3 * i + 0] = mesh.positions[i].x;
                v[3 * i + 1] = mesh.positions[i].y;
                v[3 * i + 2] = mesh.positions[i].z;
            }
            std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
            const uint32_t needs = filter.mesh_flags(uint32_t(m));
            if (needs & SurfaceFilter::kNeedsAccept) rtcSetGeometryIntersectFilterFunction(g, &intersect_filter);
            if (needs & (SurfaceFilter::kNeedsTransmittance | SurfaceFilter::kNeedsAccept))
                rtcSetGeometryOccludedFilterFunction(g, &occluded_filter);
            rtcCommitGeometry(g);
            RTCScene s = rtcNewScene(m_device);
            rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_MEDIUM);
            rtcSetSceneFlags(s, flags);
            rtcAttachGeometryByID(s, g, 0);
            rtcReleaseGeometry(g);
            rtcCommitScene(s);
            m_mesh_scenes[m] = s;
            m_bytes += mesh.positions.size() * 12 + mesh.indices.size() * 4;
        }

        // The top level: one instance per Instance, geometry ID = instance index.
        m_top = rtcNewScene(m_device);
        rtcSetSceneBuildQuality(m_top, RTC_BUILD_QUALITY_MEDIUM);
        rtcSetSceneFlags(m_top, flags);
        m_mesh_of_instance.resize(scene.instances.size());
        for (size_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& inst = scene.instances[i];
            m_mesh_of_instance[i] = inst.mesh;
            RTCScene child = m_mesh_scenes[inst.mesh];
            if (!child) continue;
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, child);
            float xfm[12];
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c) xfm[r * 4 + c] = float(inst.world_from_object(r, c));
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m_top, g, unsigned(i));
            rtcReleaseGeometry(g);
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
        QueryContext q;
        rtcInitIntersectContext(&q.rtc);
        q.filter = &m_filter;
        q.mesh_of_instance = &m_mesh_of_instance;
        q.ray = &ray;
        q.kind = kind;
        RTCRayHit rh;
        set_ray(rh.ray, ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_top, &q.rtc, &rh);
        Hit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        h.t = rh.ray.tfar;
        h.u = rh.hit.u;
        h.v = rh.hit.v;
        h.prim = rh.hit.primID;
        h.inst = rh.hit.instID[0];
        h.geom = m_mesh_of_instance[h.inst];
        return h;
    }

    Color transmittance(const Ray& ray) const override {
        if (!ray_is_traceable(ray)) return Color(1.f);
        QueryContext q;
        rtcInitIntersectContext(&q.rtc);
        q.filter = &m_filter;
        q.mesh_of_instance = &m_mesh_of_instance;
        q.ray = &ray;
        q.kind = RayKind::Shadow;
        RTCRay r;
        set_ray(r, ray);
        rtcOccluded1(m_top, &q.rtc, &r);
        if (r.tfar == -kInfinity) return Color(0.f);  // an opaque surface blocked it
        return q.transmittance;
    }

    std::string name() const override { return "embree"; }
    AccelStats stats() const override { return {m_build_seconds, m_bytes}; }

private:
    static void set_ray(RTCRay& r, const Ray& ray) {
        r.org_x = ray.org.x;
        r.org_y = ray.org.y;
        r.org_z = ray.org.z;
        r.dir_x = ray.dir.x;
        r.dir_y = ray.dir.y;
        r.dir_z = ray.dir.z;
        r.tnear = ray.tnear;
        r.tfar = ray.tfar;
        r.time = 0.f;
        r.mask = 0xffffffffu;
        r.id = 0;
        r.flags = 0;
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

    const SurfaceFilter& m_filter;
    RTCDevice m_device = nullptr;
    RTCScene m_top = nullptr;
    std::vector<RTCScene> m_mesh_scenes;
    std::vector<uint32_t> m_mesh_of_instance;
    std::mutex m_error_mutex;
    std::string m_error;
    double m_build_seconds = 0.0;
    size_t m_bytes = 0;
};

}  // namespace

void set_embree_memory_limit(size_t bytes) { g_memory_limit.store(bytes); }

std::unique_ptr<Accelerator> create_embree_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                       const EmbreeConfig& config) {
    return std::make_unique<EmbreeAccelerator>(scene, filter, config);
}

}  // namespace whitted
