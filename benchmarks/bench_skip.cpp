// `whitted bench skip [SCENE...]`: what skipping unneeded work costs and saves
// (docs/performance.md).
//
// For each scene, on one accelerator:
//   (a) the general kernel (--no-specialize) and (b) the kernel the scene analysis selects, both
//       with min_weight 0: median render time of --repeat runs (interleaved a b a b ...), rays by
//       kind, and the image difference (must be zero: the specialised kernel only skips work that
//       contributes 0);
//   (c) the specialised kernel over a sweep of min_weight (Hall & Greenberg 1983): time, rays,
//       secondary rays and the error against min_weight 0 (RMSE linear and display-referred,
//       largest pixel difference);
//   (d) the "Whitted overhead": the rays of one render are recorded (through a decorator of the
//       accelerator), then replayed through the bare accelerator with the same threads; renders
//       and replays alternate, and the ratio (render Mrays/s / replay Mrays/s) is the median over
//       the pairs. Then --repeat more pairs, each through a decorator that adds up the ticks
//       spent inside the accelerator's queries, split the render into traversal and the rest:
//       the traversal's share of the render, and its ticks against the replay's (1 = the rays
//       cost the same inside the render as bare), medians over the pairs;
//   (e) for scenes made only of triangle meshes, a private Embree scene built like the backend's
//       (one BVH per mesh, one instance per Instance, build quality MEDIUM) measures rtcIntersect1
//       against rtcIntersect4/8/16 on the recorded camera rays, rtcOccluded1 with and without an
//       occlusion filter on the recorded shadow rays, and the BVH's bytes through Embree's memory
//       monitor;
//   (f) the centre-sample camera pass without the film, one thread, in tiles with rows of up to 16
//       samples: the general kernel ray by ray, the specialised kernel ray by ray, and the
//       specialised kernel with WhittedIntegrator::trace_camera (one batch query per row: Embree
//       packets), and the Whitted overhead of each pass against a replay of its own recorded rays
//       (batches replayed as batches).
// Times are process CPU seconds with --threads 1 (robust on a shared machine) and wall-clock
// seconds otherwise; medians of --repeat runs. Writes <out>/skip.csv, skip_overhead.csv,
// skip_packets.csv, skip_camera_pass.csv and (python3 with matplotlib) the error-against-time plot of the min-weight
// sweep through scripts/plot_skip.py.
#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <time.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/ray_recording.h"
#include "importers/scene_loader.h"
#include "core/fp_mode.h"
#include "accel/embree/embree_ray.h"
#include "core/error.h"
#include "core/log.h"
#include "integrator/camera.h"
#include "integrator/render.h"
#include "output/image_output.h"

namespace whitted::app {

namespace {

/// The Whitted overhead target: render Mrays/s at least this fraction of a bare replay of the same
/// rays (issue 44; was 0.70).
constexpr double kOverheadTarget = 0.80;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The clock every figure uses: process CPU time with one thread (other processes on a shared
/// machine then cost nothing but cache pollution), wall-clock time with more threads.
bool g_cpu_clock = false;

double clock_now() {
    if (g_cpu_clock) return process_cpu_seconds();
    return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

struct BenchSkipOptions {
    std::vector<std::string> scenes;   ///< empty = the bundled scenes (default_scenes())
    int width = 320;                   ///< image width (height from the camera aspect)
    int repeat = 5;                    ///< timed runs per setting; the median is reported
    int threads = 0;                   ///< 0 = all cores
    std::string aa = "center";         ///< anti-aliasing mode (center: one camera ray per pixel)
    std::vector<float> min_weights{0.f, 1e-4f, 1e-3f, 1.f / 255.f, 0.01f, 0.03f, 0.1f};
    std::string out = "out/bench_skip";
    std::string accel = "embree";      ///< accelerator backend and options (e.g. embree:packet=8)
    float mirror_cutoff = MappingOptions{}.mirror_roughness_cutoff;  ///< glTF mapping, as --mirror-cutoff
    bool plot = true;
    bool packets = true;               ///< (e): private Embree scene for mesh-only scenes
    bool camera_pass = true;           ///< (f): camera pass, ray by ray and with batch queries
};

std::vector<std::string> default_scenes() {
    const std::string a = std::string(WHITTED_SOURCE_DIR) + "/assets/";
    return {a + "scenes/whitted1980.json", a + "scenes/transparent_shadows.json", a + "scenes/glass_mirror_room.json",
            a + "scenes/default.glb", a + "gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb",
            a + "gltf/Duck/glTF-Binary/Duck.glb"};
}

/// The 1-minute load average (the machine is shared: every figure is printed next to it).
double load_average() { return load_average_1min(); }

// ---- image differences ----

struct ImageDiff {
    uint64_t differing_pixels = 0;   ///< pixels with any channel not == (bit-exactness check)
    double max_abs = 0.0;            ///< largest channel difference (linear)
    double rmse_linear = 0.0;
    double rmse_display = 0.0;       ///< after the default OCIO view, clamped to [0, 1]
};

std::vector<float> packed(const Film& film) {
    std::vector<float> rgb(film.beauty.size() * 3);
    for (size_t i = 0; i < film.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = film.beauty[i][c];
    return rgb;
}

ImageDiff compare(const Film& a, const Film& b, const DisplayTransform& display) {
    ImageDiff d;
    std::vector<float> pa = packed(a), pb = packed(b);
    double se = 0.0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            const double x = a.beauty[i][c], y = b.beauty[i][c];
            differs |= a.beauty[i][c] != b.beauty[i][c];
            d.max_abs = std::max(d.max_abs, std::abs(x - y));
            se += (x - y) * (x - y);
        }
        d.differing_pixels += differs;
    }
    d.rmse_linear = std::sqrt(se / double(pa.size()));
    display.apply(pa.data(), pa.size() / 3);
    display.apply(pb.data(), pb.size() / 3);
    se = 0.0;
    for (size_t i = 0; i < pa.size(); ++i) {
        const double x = std::isnan(pa[i]) ? 0.0 : std::clamp(pa[i], 0.f, 1.f);
        const double y = std::isnan(pb[i]) ? 0.0 : std::clamp(pb[i], 0.f, 1.f);
        se += (x - y) * (x - y);
    }
    d.rmse_display = std::sqrt(se / double(pa.size()));
    return d;
}

// ---- timed renders ----

struct Measured {
    Film film;
    RenderStats stats;                ///< of the last run (ray counts are the same every run)
    double median_seconds = 0.0, min_seconds = 0.0;
    double load = 0.0;                ///< 1-minute load average after the runs
};

/// Renders every setting of `settings` `repeat` times, interleaved (A B C A B C ...) so that a
/// change of the machine's load affects every setting alike.
std::vector<Measured> measure(const Renderer& r, const AaSettings& aa, const std::vector<IntegratorSettings>& settings,
                              int repeat) {
    std::vector<Measured> m(settings.size());
    std::vector<std::vector<double>> t(settings.size());
    for (int i = 0; i < std::max(1, repeat); ++i)
        for (size_t k = 0; k < settings.size(); ++k) {
            RenderStats st;
            const double start = clock_now();
            m[k].film = r.render(aa, settings[k], r.accelerator(), &st);
            t[k].push_back(clock_now() - start);
            m[k].stats = st;
        }
    for (size_t k = 0; k < settings.size(); ++k) {
        m[k].median_seconds = median(t[k]);
        m[k].min_seconds = *std::min_element(t[k].begin(), t[k].end());
        m[k].load = load_average();
    }
    return m;
}

// ---- ray recording and replay (the Whitted overhead) ----

/// Seconds to replay `rays` through `accel` in blocks of about 1024 consecutive rays on `threads`
/// threads (median of `repeat` runs). Blocks start at query boundaries, so recorded batch queries
/// (rows of camera rays) are replayed as batches: packets where the render used packets.
double replay_seconds(const Accelerator& accel, const std::vector<RecordedRay>& rays, int threads, int repeat) {
    std::vector<size_t> starts{0};
    for (size_t i = 0; i < rays.size(); ++i)
        if (i - starts.back() >= 1024 && rays[i].batch != 0) starts.push_back(i);
    starts.push_back(rays.size());
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(std::max(1, threads)));
    std::vector<double> t;
    for (int run = 0; run < std::max(1, repeat); ++run) {
        const double start = clock_now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, starts.size() - 1), [&](const tbb::blocked_range<size_t>& r) {
            const ScopedFlushDenormals ftz;  // the mode the render traces in
            std::vector<Ray> batch;
            std::vector<Hit> hits;
            float sink = 0.f;
            for (size_t b = r.begin(); b != r.end(); ++b) sink += replay(accel, rays, starts[b], starts[b + 1], batch, hits);
            volatile float keep = sink;
            (void)keep;
        });
        t.push_back(clock_now() - start);
    }
    return median(t);
}

/// The rays of `rays` regrouped as a batched integrator would trace them (issue 44, item 1): each
/// camera query starts a segment (its rays' trees follow it in the log, each thread's log in
/// order); within a segment the camera query stays first, then the shadow rays toward each light
/// (the same end point within 1e-4 of its magnitude, or the same direction for rays without an
/// end) and the reflection and refraction rays of each kind are each one batch query, in order of
/// first appearance. The same rays, so a replay of both orders bounds what gathering can buy in
/// traversal alone.
std::vector<RecordedRay> gathered_order(const std::vector<RecordedRay>& rays) {
    std::vector<RecordedRay> out;
    out.reserve(rays.size());
    struct Group {
        bool shadow;
        RayKind kind;
        bool finite;
        Vec3f key;  // end point (finite shadow rays) or direction
        std::vector<size_t> members;
    };
    std::vector<Group> groups;
    auto flush = [&] {
        for (const Group& g : groups)
            for (size_t k = 0; k < g.members.size(); ++k) {
                RecordedRay r = rays[g.members[k]];
                r.batch = k == 0 ? uint32_t(g.members.size()) : 0u;
                out.push_back(r);
            }
        groups.clear();
    };
    for (size_t i = 0; i < rays.size();) {
        const RecordedRay& r = rays[i];
        if (!r.shadow && r.kind == RayKind::Camera && r.batch != 0) {  // a new segment
            flush();
            const size_t n = std::max<size_t>(1, r.batch);
            for (size_t k = i; k < i + n && k < rays.size(); ++k) out.push_back(rays[k]);
            i += n;
            continue;
        }
        const bool finite = r.shadow && std::isfinite(r.ray.tfar);
        const Vec3f key = finite ? r.ray.org + r.ray.dir * r.ray.tfar : r.ray.dir;
        Group* into = nullptr;
        for (Group& g : groups) {
            if (g.shadow != r.shadow || g.kind != r.kind || g.finite != finite) continue;
            if (!r.shadow) {
                into = &g;
                break;
            }
            const float tol = finite ? 1e-4f * std::max(1.f, max_abs(key)) : 0.f;
            if (max_abs(g.key - key) <= tol) {
                into = &g;
                break;
            }
        }
        if (!into) {
            groups.push_back({r.shadow, r.kind, finite, key, {}});
            into = &groups.back();
        }
        into->members.push_back(i);
        ++i;
    }
    flush();
    return out;
}

// ---- (f) the camera pass: general, specialised, specialised + packets ----

/// One centre sample per pixel in tiles of `tile` pixels, each tile row cut into rows of up to 16
/// samples (what render.cpp's tile loops would batch), without the film, in the calling thread.
/// `packets`: each row through WhittedIntegrator::trace_camera (one batch query in the specialised
/// kernels); otherwise trace() ray by ray. Returns the radiance per pixel, row-major.
std::vector<Color> camera_pass(const CameraModel& camera, const WhittedIntegrator& integrator, ImageSize size, int tile,
                               bool packets, RayCounters& rc) {
    const ScopedFlushDenormals ftz;  // the mode the render traces in (the Renderer restores the caller's)
    std::vector<Color> image(size_t(size.width) * size_t(size.height));
    const RayCone cone = camera.pixel_cone();
    std::array<Ray, 16> rays;
    std::array<Color, 16> radiance;
    for (int ty = 0; ty < size.height; ty += tile)
        for (int tx = 0; tx < size.width; tx += tile)
            for (int y = ty; y < std::min(size.height, ty + tile); ++y)
                for (int x0 = tx; x0 < std::min(size.width, tx + tile); x0 += 16) {
                    const size_t n = size_t(std::min({16, size.width - x0, tx + tile - x0}));
                    camera.generate_row(x0 + 0.5, 1.0, y + 0.5, std::span(rays.data(), n));
                    if (packets) {
                        integrator.trace_camera(std::span(rays.data(), n), std::span(radiance.data(), n), rc, cone);
                    } else {
                        for (size_t i = 0; i < n; ++i)
                            radiance[i] = integrator.trace(rays[i], RayKind::Camera, 0, rc, nullptr, cone);
                    }
                    std::copy_n(radiance.begin(), n, image.begin() + ptrdiff_t(size_t(y) * size_t(size.width) + size_t(x0)));
                }
    return image;
}

uint64_t differing(const std::vector<Color>& a, const std::vector<Color>& b) {
    uint64_t d = 0;
    for (size_t i = 0; i < a.size(); ++i) d += !(a[i] == b[i]);
    return d;
}

// ---- (e) a private Embree scene: packets, filters, BVH bytes ----

std::atomic<int64_t> g_embree_bytes{0};
std::atomic<int64_t> g_embree_peak{0};

bool memory_monitor(void*, ssize_t bytes, bool) {
    const int64_t now = g_embree_bytes.fetch_add(int64_t(bytes)) + int64_t(bytes);
    int64_t peak = g_embree_peak.load();
    while (now > peak && !g_embree_peak.compare_exchange_weak(peak, now)) {
    }
    return true;
}

/// An occlusion filter that accepts every hit: the bare cost of having a filter at all (the
/// backend no longer installs one on opaque meshes, single-sided ones included: shadow queries
/// read only kNeedsTransmittance).
void accept_all_filter(const RTCFilterFunctionNArguments* args) {
    volatile int sink = 0;
    for (unsigned i = 0; i < args->N; ++i) sink = sink + args->valid[i];
}

class PrivateEmbree {
public:
    PrivateEmbree(const Scene& scene, bool occlusion_filter) {
        m_device = rtcNewDevice("");
        if (!m_device) throw Error("bench skip: cannot create an Embree device");
        rtcSetDeviceMemoryMonitorFunction(m_device, &memory_monitor, nullptr);
        const int64_t before = g_embree_bytes.load();
        g_embree_peak.store(before);
        // As the backend: one scene per mesh (MEDIUM quality), one instance per Instance.
        std::vector<RTCScene> mesh_scenes(scene.meshes.size(), nullptr);
        for (size_t m = 0; m < scene.meshes.size(); ++m) {
            const Mesh& mesh = scene.meshes[m];
            if (mesh.triangle_count() == 0) continue;
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), mesh.positions.size() + 1));
            auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(uint32_t), mesh.triangle_count()));
            std::memcpy(v, mesh.positions.data(), mesh.positions.size() * sizeof(Vec3f));
            std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
            if (occlusion_filter) rtcSetGeometryOccludedFilterFunction(g, &accept_all_filter);
            rtcCommitGeometry(g);
            RTCScene s = rtcNewScene(m_device);
            rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_MEDIUM);
            rtcAttachGeometryByID(s, g, 0);
            rtcReleaseGeometry(g);
            rtcCommitScene(s);
            mesh_scenes[m] = s;
            m_vertex_index_bytes += (mesh.positions.size() + 1) * 12 + mesh.indices.size() * 4;
        }
        m_top = rtcNewScene(m_device);
        rtcSetSceneBuildQuality(m_top, RTC_BUILD_QUALITY_MEDIUM);
        for (size_t i = 0; i < scene.instances.size(); ++i) {
            RTCScene child = mesh_scenes[scene.instances[i].mesh];
            if (!child) continue;
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, child);
            float xfm[12];
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c) xfm[r * 4 + c] = float(scene.instances[i].world_from_object(r, c));
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m_top, g, unsigned(i));
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(m_top);
        for (RTCScene s : mesh_scenes)
            if (s) rtcReleaseScene(s);  // the instances hold references
        m_bytes = g_embree_bytes.load() - before;
        m_peak_bytes = g_embree_peak.load() - before;
    }
    ~PrivateEmbree() {
        if (m_top) rtcReleaseScene(m_top);
        if (m_device) rtcReleaseDevice(m_device);
    }
    PrivateEmbree(const PrivateEmbree&) = delete;
    PrivateEmbree& operator=(const PrivateEmbree&) = delete;

    /// Bytes Embree holds for the scene (vertex and index buffers included), and at peak in the build.
    int64_t bytes() const { return m_bytes; }
    int64_t peak_bytes() const { return m_peak_bytes; }
    int64_t vertex_index_bytes() const { return int64_t(m_vertex_index_bytes); }

    /// Mrays/s of closest-hit queries on `rays` in packets of `width` (1, 4, 8, 16) consecutive rays.
    double intersect_mrays(const std::vector<Ray>& rays, int width, int threads, int repeat) const {
        return mrays(rays, threads, repeat, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; i += size_t(width)) {
                const size_t n = std::min(size_t(width), end - i);
                switch (width) {
                    case 1: trace1(rays[i]); break;
                    case 4: traceN<RTCRayHit4, 4>(&rays[i], n, rtcIntersect4); break;
                    case 8: traceN<RTCRayHit8, 8>(&rays[i], n, rtcIntersect8); break;
                    default: traceN<RTCRayHit16, 16>(&rays[i], n, rtcIntersect16); break;
                }
            }
        });
    }
    /// Mrays/s of rtcOccluded1 on `rays`.
    double occluded_mrays(const std::vector<Ray>& rays, int threads, int repeat) const {
        return mrays(rays, threads, repeat, [&](size_t begin, size_t end) {
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            for (size_t i = begin; i < end; ++i) {
                RTCRay r;
                set_rtc_ray(r, rays[i]);
                rtcOccluded1(m_top, &ctx, &r);
            }
        });
    }

private:
    template <typename Body>
    double mrays(const std::vector<Ray>& rays, int threads, int repeat, Body&& body) const {
        if (rays.empty()) return 0.0;
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(std::max(1, threads)));
        std::vector<double> t;
        for (int run = 0; run < std::max(1, repeat); ++run) {
            const double start = clock_now();
            // Blocks of 1024 rays (a multiple of every packet width).
            tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
                const ScopedFlushDenormals ftz;  // the mode the render traces in
                body(r.begin(), r.end());
            });
            t.push_back(clock_now() - start);
        }
        return double(rays.size()) / median(t) * 1e-6;
    }
    void trace1(const Ray& ray) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        RTCRayHit rh;
        set_rtc_ray(rh.ray, ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_top, &ctx, &rh);
    }
    template <typename Packet, int N, typename Fn>
    void traceN(const Ray* rays, size_t n, Fn fn) const {
        alignas(64) Packet p;
        alignas(64) int valid[N];
        for (int k = 0; k < N; ++k) {
            valid[k] = size_t(k) < n ? -1 : 0;
            const Ray& ray = rays[size_t(k) < n ? size_t(k) : 0];
            p.ray.org_x[k] = ray.org.x;
            p.ray.org_y[k] = ray.org.y;
            p.ray.org_z[k] = ray.org.z;
            p.ray.dir_x[k] = ray.dir.x;
            p.ray.dir_y[k] = ray.dir.y;
            p.ray.dir_z[k] = ray.dir.z;
            p.ray.tnear[k] = ray.tnear;
            p.ray.tfar[k] = ray.tfar;
            p.ray.time[k] = 0.f;
            p.ray.mask[k] = 0xffffffffu;
            p.ray.id[k] = 0;
            p.ray.flags[k] = 0;
            p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        fn(valid, m_top, &ctx, &p);
    }

    RTCDevice m_device = nullptr;
    RTCScene m_top = nullptr;
    int64_t m_bytes = 0, m_peak_bytes = 0;
    size_t m_vertex_index_bytes = 0;
};

bool mesh_only(const Scene& s) { return s.spheres.empty() && s.planes.empty() && !s.meshes.empty(); }

std::string label_of(const std::string& path) { return fs::path(path).stem().string(); }

int run_bench_skip(const BenchSkipOptions& o) {
    const std::vector<std::string> scenes = o.scenes.empty() ? default_scenes() : o.scenes;
    const fs::path out(o.out);
    fs::create_directories(out);
    const DisplayTransform display(ColorSettings{});
    std::ofstream csv(out / "skip.csv"), ocsv(out / "skip_overhead.csv"), pcsv(out / "skip_packets.csv");
    csv << "scene,variant,kernel,min_weight,clock,median_s,min_s,load,camera,shadow,reflection,refraction,secondary,total,"
           "mrays_per_s,shadow_skipped_unreached,shadow_skipped_facing,shadow_skipped_zero,secondary_skipped_cutoff,differing_pixels,"
           "max_abs,rmse_linear,rmse_display\n";
    ocsv << "scene,threads,clock,rays,camera,shadow,secondary,render_s,render_mrays,replay_s,replay_mrays,overhead_ratio,load,"
            "render_traversal_share,traversal_render_over_replay\n";
    pcsv << "scene,query,width,threads,mrays_per_s,load\n";
    std::ofstream ccsv(out / "skip_camera_pass.csv");
    ccsv << "scene,variant,min_weight,clock,median_s,rays,camera,mrays_per_s,speedup_vs_general,differing_pixels,"
            "replay_s,replay_mrays,overhead_ratio,load\n";
    const int hw = tbb::this_task_arena::max_concurrency();
    const int threads = o.threads > 0 ? o.threads : hw;
    g_cpu_clock = threads == 1;
    std::printf("bench skip: %d thread(s), %s anti-aliasing, width %d, median of %d run(s), %s seconds; load %.2f\n",
                threads, o.aa.c_str(), o.width, o.repeat, g_cpu_clock ? "CPU" : "wall-clock", load_average());

    for (const std::string& path : scenes) {
        const std::string label = label_of(path);
        Scene scene = load_scene(path);
        RenderSettings rs;
        apply_scene_settings(scene.settings, rs);
        rs.width = o.width;
        rs.height = 0;
        rs.threads = o.threads;
        rs.accel = o.accel;
        rs.aa.mode = parse_aa_mode(o.aa);
        rs.mapping.mirror_roughness_cutoff = o.mirror_cutoff;
        rs.progress = false;
        Renderer renderer(scene, rs);
        const ImageSize size = renderer.image_size();
        const SceneAnalysis& an = renderer.view().analysis();
        std::printf("\n== %s: %dx%d, %zu triangles, %zu spheres, %zu planes, %zu lights, max depth %d, build %.3fs\n",
                    label.c_str(), size.width, size.height, scene.instanced_triangle_count(), scene.spheres.size(),
                    scene.planes.size(), scene.lights.size(), rs.integrator.max_depth, renderer.build_seconds());
        std::printf("   analysis: opaque=%s recursive=%s mirror=%s transmission=%s blend=%s varying=%s; kernel %s\n",
                    an.features.opaque() ? "yes" : "no", an.features.recursive() ? "yes" : "no",
                    an.features.mirror ? "yes" : "no", an.features.transmission ? "yes" : "no",
                    an.features.alpha_blend ? "yes" : "no", an.features.varying ? "yes" : "no",
                    kernel_name(renderer.kernel()).c_str());

        auto row = [&](const char* variant, const KernelFeatures& k, float mw, const Measured& m, const ImageDiff& d) {
            const RayCounters& r = m.stats.rays;
            const double mr = double(r.total()) / m.median_seconds * 1e-6;
            std::printf("   %-12s %-9s mw=%-9.6g %8.4fs (min %8.4fs) cam %9llu shd %9llu refl %9llu refr %9llu "
                        "%7.2f Mr/s | diff px %7llu max %.2e rmse %.2e disp %.2e | load %.2f\n",
                        variant, k == kGeneralKernel ? "general" : "special", double(mw), m.median_seconds,
                        m.min_seconds, (unsigned long long)r.camera, (unsigned long long)r.shadow,
                        (unsigned long long)r.reflection, (unsigned long long)r.refraction, mr,
                        (unsigned long long)d.differing_pixels, d.max_abs, d.rmse_linear, d.rmse_display, m.load);
            std::fflush(stdout);
            csv << fmt::format("{},{},\"{}\",{:g},{},{:.6f},{:.6f},{:.2f},{},{},{},{},{},{},{:.4f},{},{},{},{},{},{:.6g},{:.6g},{:.6g}\n",
                               label, variant, kernel_name(k), mw, g_cpu_clock ? "cpu" : "wall", m.median_seconds, m.min_seconds, m.load, r.camera,
                               r.shadow, r.reflection, r.refraction, r.secondary(), r.total(), mr,
                               r.shadow_skipped_unreached, r.shadow_skipped_facing, r.shadow_skipped_zero, r.secondary_skipped_cutoff,
                               d.differing_pixels, d.max_abs, d.rmse_linear, d.rmse_display);
        };

        // (a) general and (b) specialised, min_weight 0: identical images.
        IntegratorSettings general = rs.integrator;
        general.min_weight = 0.f;
        general.specialize = false;
        IntegratorSettings special = general;
        special.specialize = true;
        const KernelFeatures kspecial = select_kernel(an.features, special);
        std::vector<Measured> pair = measure(renderer, rs.aa, {general, special}, o.repeat);
        const Measured& mg = pair[0];
        const Measured& ms = pair[1];
        row("general", kGeneralKernel, 0.f, mg, ImageDiff{});
        const ImageDiff ds = compare(ms.film, mg.film, display);
        row("specialised", kspecial, 0.f, ms, ds);
        std::printf("   speed-up specialised / general: %.3fx (medians), images %s\n",
                    mg.median_seconds / ms.median_seconds, ds.differing_pixels == 0 ? "identical" : "DIFFER");
        write_image(ms.film, (out / (label + ".png")).string(), OutputSettings{});

        // (f) the camera pass: general / specialised ray by ray / specialised + packets (one thread).
        if (o.camera_pass) {
            const CameraModel camera(scene.cameras[size_t(rs.camera)], size.width, size.height);
            struct Variant {
                const char* name;
                IntegratorSettings settings;
                bool packets;
            };
            for (const float mw : {0.f, 1.f / 255.f}) {
                IntegratorSettings g = general, sp = special;
                g.min_weight = sp.min_weight = mw;
                const Variant variants[] = {{"general", g, false}, {"specialised", sp, false}, {"specialised+packets", sp, true}};
                std::vector<std::vector<double>> t(std::size(variants));
                std::vector<std::vector<Color>> images(std::size(variants));
                std::vector<RayCounters> counts(std::size(variants));
                for (int run = 0; run < std::max(1, o.repeat); ++run)
                    for (size_t k = 0; k < std::size(variants); ++k) {
                        const WhittedIntegrator integrator(renderer.view(), renderer.accelerator(), variants[k].settings);
                        RayCounters rc;
                        const double start = clock_now();
                        images[k] = camera_pass(camera, integrator, size, rs.tile_size, variants[k].packets, rc);
                        t[k].push_back(clock_now() - start);
                        counts[k] = rc;
                    }
                const double load = load_average();
                const double tg = median(t[0]);
                for (size_t k = 0; k < std::size(variants); ++k) {
                    // Its own rays recorded (batches kept) and replayed through the bare accelerator.
                    RecordingAccelerator recorder(renderer.accelerator());
                    const WhittedIntegrator integrator(renderer.view(), recorder, variants[k].settings);
                    RayCounters rc;
                    (void)camera_pass(camera, integrator, size, rs.tile_size, variants[k].packets, rc);
                    const std::vector<RecordedRay> rays = recorder.rays();
                    const double replay = replay_seconds(renderer.accelerator(), rays, 1, o.repeat);
                    const double tk = median(t[k]);
                    const double mr = double(rays.size()) / tk * 1e-6, replay_mr = double(rays.size()) / replay * 1e-6;
                    const uint64_t diff = differing(images[k], images[0]);
                    std::printf("   camera pass %-20s mw=%-9.6g %8.4fs %9zu rays %7.2f Mr/s, %.3fx general, diff px %llu | "
                                "replay %7.2f Mr/s, overhead ratio %.3f | load %.2f\n",
                                variants[k].name, double(mw), tk, rays.size(), mr, tg / tk, (unsigned long long)diff,
                                replay_mr, mr / replay_mr, load);
                    ccsv << fmt::format("{},{},{:g},{},{:.6f},{},{},{:.4f},{:.4f},{},{:.6f},{:.4f},{:.4f},{:.2f}\n", label,
                                        variants[k].name, mw, g_cpu_clock ? "cpu" : "wall", tk, rays.size(),
                                        counts[k].camera, mr, tg / tk, diff, replay, replay_mr, mr / replay_mr, load);
                }
            }
            ccsv.flush();
        }

        // (c) the min_weight sweep (specialised kernel, interleaved), errors against min_weight 0.
        std::vector<IntegratorSettings> sweep;
        for (const float mw : o.min_weights) {
            if (mw == 0.f) continue;
            sweep.push_back(special);
            sweep.back().min_weight = mw;
        }
        const std::vector<Measured> swept = measure(renderer, rs.aa, sweep, o.repeat);
        for (size_t k = 0; k < sweep.size(); ++k) {
            const ImageDiff d = compare(swept[k].film, ms.film, display);
            row("min_weight", kspecial, sweep[k].min_weight, swept[k], d);
            if (sweep[k].min_weight != 1.f / 255.f) continue;
            // Target: >= 1.5x fewer secondary rays on mirror/glass scenes, RMSE <= 1e-3 (linear).
            const uint64_t before = ms.stats.rays.secondary(), after = swept[k].stats.rays.secondary();
            const double fewer = after ? double(before) / double(after) : 0.0;
            std::printf("   min_weight 1/255: secondary rays %llu -> %llu (%.2fx fewer), time %.3fx, RMSE %.2e linear "
                        "(target >= 1.5x with RMSE <= 1e-3: %s)\n",
                        (unsigned long long)before, (unsigned long long)after, fewer,
                        ms.median_seconds / swept[k].median_seconds, d.rmse_linear,
                        before == 0 ? "no secondary rays" : fewer >= 1.5 && d.rmse_linear <= 1e-3 ? "met" : "NOT met");
        }

        // (d) Whitted overhead at the CLI default min_weight: record, then replay the same rays.
        {
            IntegratorSettings is = special;
            is.min_weight = 1.f / 255.f;
            RecordingAccelerator recorder(renderer.accelerator());
            RenderStats st;
            (void)renderer.render(rs.aa, is, recorder, &st);
            const std::vector<RecordedRay> rays = recorder.rays();
            // Render and replay alternate (render, replay, render, replay ...): on a shared machine
            // the load drifts within seconds, and timing all renders before all replays let it skew
            // the ratio by +-0.1 between identical runs. Each pair gives a ratio; the median is kept.
            std::vector<double> render_t, replay_t, pair_ratio;
            for (int i = 0; i < std::max(1, o.repeat); ++i) {
                const double start = clock_now();
                (void)renderer.render(rs.aa, is, renderer.accelerator(), nullptr);
                render_t.push_back(clock_now() - start);
                replay_t.push_back(replay_seconds(renderer.accelerator(), rays, threads, 1));
                pair_ratio.push_back(replay_t.back() / render_t.back());
            }
            const double render_s = median(render_t), replay = median(replay_t), ratio = median(pair_ratio);
            // Where the render's time goes: the ticks inside the accelerator against the whole
            // render, and against a replay of the same rays through the same decorator.
            // Pairs again (render, replay, ...), medians of each fraction.
            std::vector<double> shares, vs_replay;
            for (int i = 0; i < std::max(1, o.repeat); ++i) {
                const TimingAccelerator in_render(renderer.accelerator()), in_replay(renderer.accelerator());
                const uint64_t t0 = ticks();
                (void)renderer.render(rs.aa, is, in_render, nullptr);
                const uint64_t render_ticks = ticks() - t0;
                (void)replay_seconds(in_replay, rays, threads, 1);
                // Summed over the threads: against the render's ticks on every thread (all busy).
                shares.push_back(double(in_render.traversal_ticks()) /
                                 (double(std::max<uint64_t>(1, render_ticks)) * double(threads)));
                vs_replay.push_back(double(in_render.traversal_ticks()) /
                                    double(std::max<uint64_t>(1, in_replay.traversal_ticks())));
            }
            const double traversal_share = median(shares), traversal_vs_replay = median(vs_replay);
            const double render_mr = double(rays.size()) / render_s * 1e-6;
            const double replay_mr = double(rays.size()) / replay * 1e-6;
            const double load = load_average();
            std::printf("   whitted overhead (min_weight 1/255): %zu rays, render %.4fs = %.2f Mrays/s, bare replay %.4fs "
                        "= %.2f Mrays/s, ratio %.3f (median of %zu render/replay pairs; target >= %.2f: %s) | load %.2f\n",
                        rays.size(), render_s, render_mr, replay, replay_mr, ratio, pair_ratio.size(), kOverheadTarget,
                        ratio >= kOverheadTarget ? "met" : "NOT met", load);
            std::printf("   traversal inside the render: %.1f%% of its time (the rest: shading, surfaces, camera, "
                        "film); the same queries take %.3fx the replay's traversal time\n",
                        100.0 * traversal_share, traversal_vs_replay);
            // What gathering the trees' rays into batch queries could save in traversal (issue 44,
            // item 1): the same rays replayed in the recorded order and regrouped, alternately.
            {
                const std::vector<RecordedRay> grouped = gathered_order(rays);
                std::vector<double> as_recorded, regrouped, gain;
                for (int i = 0; i < std::max(1, o.repeat); ++i) {
                    as_recorded.push_back(replay_seconds(renderer.accelerator(), rays, threads, 1));
                    regrouped.push_back(replay_seconds(renderer.accelerator(), grouped, threads, 1));
                    gain.push_back(regrouped.back() / as_recorded.back());
                }
                size_t queries = 0;
                for (const RecordedRay& r : grouped) queries += r.batch != 0;
                std::printf("   gathered replay: each camera batch's trees regrouped (shadow rays per light, reflection "
                            "and refraction rays per kind: %zu queries for %zu rays) %.4fs against %.4fs in the "
                            "recorded order: %.3fx the time (median of %zu pairs)\n",
                            queries, grouped.size(), median(regrouped), median(as_recorded), median(gain), gain.size());
            }
            ocsv << fmt::format("{},{},{},{},{},{},{},{:.6f},{:.4f},{:.6f},{:.4f},{:.4f},{:.2f},{:.4f},{:.4f}\n", label,
                                threads, g_cpu_clock ? "cpu" : "wall", rays.size(), st.rays.camera, st.rays.shadow,
                                st.rays.secondary(), render_s, render_mr, replay, replay_mr, ratio, load,
                                traversal_share, traversal_vs_replay);

            // (e) packets, filters and BVH bytes on a private Embree scene (meshes only).
            if (o.packets && mesh_only(scene)) {
                std::vector<Ray> camera, shadow;
                std::vector<RecordedRay> camera_rec, shadow_rec;
                for (const RecordedRay& r : rays) {
                    if (r.shadow) {
                        shadow.push_back(r.ray);
                        shadow_rec.push_back(r);
                    } else if (r.kind == RayKind::Camera) {
                        camera.push_back(r.ray);
                        camera_rec.push_back(r);
                    }
                }
                std::vector<int> thread_counts{1};
                if (threads > 1) thread_counts.push_back(threads);
                {
                    PrivateEmbree e(scene, false);
                    const double tris = double(std::max<size_t>(1, scene.instanced_triangle_count()));
                    std::printf("   embree memory monitor: %lld bytes (%.1f B/triangle; vertex+index buffers %.1f B/triangle), "
                                "build peak %.1f B/triangle; scene data %.1f B/triangle\n",
                                (long long)e.bytes(), double(e.bytes()) / tris, double(e.vertex_index_bytes()) / tris,
                                double(e.peak_bytes()) / tris, double(an.scene_bytes) / tris);
                    pcsv << fmt::format("{},embree_bytes_per_triangle,0,0,{:.2f},0\n", label, double(e.bytes()) / tris);
                    pcsv << fmt::format("{},scene_bytes_per_triangle,0,0,{:.2f},0\n", label, double(an.scene_bytes) / tris);
                    for (int t : thread_counts) {
                        // The same rays through the renderer's backend (its filters: single-sided
                        // culling for camera rays, transmittance callbacks for shadow rays).
                        const double backend_cam = camera_rec.empty() ? 0.0
                            : double(camera_rec.size()) / replay_seconds(renderer.accelerator(), camera_rec, t, o.repeat) * 1e-6;
                        const double backend_shd = shadow_rec.empty() ? 0.0
                            : double(shadow_rec.size()) / replay_seconds(renderer.accelerator(), shadow_rec, t, o.repeat) * 1e-6;
                        std::printf("   backend (Accelerator, with its filters), %d thread(s): camera %.2f, shadow %.2f Mrays/s\n",
                                    t, backend_cam, backend_shd);
                        pcsv << fmt::format("{},backend_intersect,1,{},{:.4f},{:.2f}\n", label, t, backend_cam, load_average());
                        pcsv << fmt::format("{},backend_transmittance,1,{},{:.4f},{:.2f}\n", label, t, backend_shd, load_average());
                        std::printf("   camera rays, %d thread(s):", t);
                        for (int width : {1, 4, 8, 16}) {
                            const double mr = e.intersect_mrays(camera, width, t, o.repeat);
                            std::printf("  rtcIntersect%d %.2f", width, mr);
                            pcsv << fmt::format("{},intersect,{},{},{:.4f},{:.2f}\n", label, width, t, mr, load_average());
                        }
                        const double occ = e.occluded_mrays(shadow, t, o.repeat);
                        std::printf("  Mrays/s | shadow rtcOccluded1 %.2f", occ);
                        pcsv << fmt::format("{},occluded,1,{},{:.4f},{:.2f}\n", label, t, occ, load_average());
                        PrivateEmbree f(scene, true);
                        const double occ_f = f.occluded_mrays(shadow, t, o.repeat);
                        std::printf(", with an occlusion filter %.2f Mrays/s | load %.2f\n", occ_f, load_average());
                        pcsv << fmt::format("{},occluded_filter,1,{},{:.4f},{:.2f}\n", label, t, occ_f, load_average());
                    }
                }
            }
        }
        csv.flush();
        ocsv.flush();
        pcsv.flush();
    }
    std::printf("\nwrote %s, %s, %s, %s\n", (out / "skip.csv").c_str(), (out / "skip_overhead.csv").c_str(),
                (out / "skip_packets.csv").c_str(), (out / "skip_camera_pass.csv").c_str());

    if (o.plot) {
        const fs::path script = fs::path(WHITTED_SOURCE_DIR) / "scripts" / "plot_skip.py";
        const std::string python = default_python();
        const std::string cmd = fmt::format("{} '{}' '{}' '{}'", python, script.string(), (out / "skip.csv").string(),
                                            (out / "skip_min_weight.png").string());
        if (std::system(cmd.c_str()) != 0) log_warning("bench skip: no plot (needs python3-matplotlib): {}", cmd);
    }
    return 0;
}

}  // namespace

Command register_bench_skip(CLI::App& bench) {
    auto o = std::make_shared<BenchSkipOptions>();
    CLI::App* app = bench.add_subcommand(
        "skip", "Scene-aware specialisation, adaptive ray-tree depth, Whitted overhead (docs/performance.md)");
    app->add_option("scenes", o->scenes, "Scene files (default: the bundled scenes and two glTF assets)");
    app->add_option("--width", o->width, "Image width (height from the camera aspect)")->check(CLI::Range(8, 8192))
        ->capture_default_str();
    app->add_option("--repeat", o->repeat, "Timed runs per setting (the median is reported)")->check(CLI::Range(1, 100))
        ->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))
        ->capture_default_str();
    app->add_option("--aa", o->aa, "Anti-aliasing mode: center, corners, adaptive, stratified")
        ->check(CLI::IsMember({"center", "corners", "adaptive", "stratified"}))->capture_default_str();
    app->add_option("--min-weights", o->min_weights, "The min_weight sweep")->delimiter(',')->capture_default_str();
    app->add_option("--mirror-cutoff", o->mirror_cutoff,
                    "glTF roughness at which mirror reflection has faded to 0 (0 = no glTF mirrors)")
        ->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
    app->add_option("--accel", o->accel, "Accelerator backend with options (docs/accelerators.md)")->capture_default_str();
    app->add_option("-o,--out", o->out, "Output directory: CSVs, images, plot")->capture_default_str();
    app->add_flag("!--no-plot", o->plot, "Do not run scripts/plot_skip.py");
    app->add_flag("!--no-camera-pass", o->camera_pass, "Skip (f), the camera pass with and without packets");
    app->add_flag("!--no-packets", o->packets, "Skip the private Embree scene (packets, filters, BVH bytes)");
    return Command{app, [o] { return run_bench_skip(*o); }};
}

}  // namespace whitted::app
