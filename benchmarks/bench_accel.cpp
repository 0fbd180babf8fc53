// `whitted bench accel`: build time, memory and ray throughput of every accelerator on procedural
// scenes of growing size and on real assets (docs/accelerators.md).
//
// Scenes: our own generators `spheres` (tessellated spheres on a grid), `soup` (random
// triangles), `terrain` (a height field), each at 1k, 10k, 100k, 1M and 5M triangles (5M for
// embree and bvh only), and scene files (`assets/scenes/default.glb`, `glass_mirror_room.json`)
// at their own size. The rays are those of a real render: each scene is rendered once with the
// Whitted integrator through a RecordingAccelerator around the in-house `bvh` (one ray per pixel
// centre, one thread, so the log is in tile order and the same every run), and its camera rays
// (coherent), shadow rays and secondary rays (reflection and refraction: incoherent) are replayed
// through every backend. The generated scenes carry a documented bench material (bench_glass()) so
// that the render has secondary rays; scene files keep their own materials. Per backend and size:
// build time, bytes per triangle, nodes, SAH cost, and Mrays/s of each ray kind on 1 and 2
// threads. Before a figure is printed the backend's answers are validated against `brute`
// (<= 100k triangles) or `bvh` on a few thousand of the recorded rays. Each cell has a time
// budget; cells expected to exceed it are skipped and listed. Writes CSV and, when
// python3-matplotlib is installed, a log-log PNG via scripts/plot_accel.py.
//
// `--ratio` instead compares the backends on one thread, interleaved (run_ratio): time per ray
// and its ratio to the first backend (Embree), the median over `--repeats` rounds.
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/ray_recording.h"
#include "importers/mesh_normals.h"
#include "importers/scene_loader.h"
#include "accel/accelerator.h"
#include "accel/factory/create_accelerator.h"
#include "core/error.h"
#include "core/log.h"
#include "integrator/render.h"
#include "scene/scene.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchAccelOptions {
    std::vector<std::string> accels{"embree", "bvh", "grid", "octree", "kdop", "brute"};
    std::vector<std::string> scenes{"spheres", "soup", "terrain", "assets/scenes/default.glb",
                                    "assets/scenes/glass_mirror_room.json"};
    std::vector<long> sizes{1000, 10000, 100000, 1000000, 5000000};
    std::vector<int> threads{1, 2};
    int rays = 1 << 18;             ///< camera rays (a 512x512 render); shadow and secondary rays are
                                    ///< thinned to at most this many each
    double budget = 60.0;           ///< seconds per (scene, size, backend) cell
    std::string out = "out/bench_accel";
    std::string precision = "float";
    std::string bv = "aabb";
    bool ratio = false;             ///< --ratio: interleaved one-thread timing, ratios to the first backend
    int repeats = 5;                ///< --ratio: interleaved repetitions (the median is reported)
};

class OpaqueFilter final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }
    uint32_t mesh_flags(uint32_t) const override { return 0; }
};

// ---- procedural scenes ----

void add_sphere(Mesh& m, Vec3f c, float r, int rings, int segs) {
    const uint32_t base = uint32_t(m.positions.size());
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j <= segs; ++j) {
            const float th = kPi * float(i) / float(rings), ph = 2.f * kPi * float(j) / float(segs);
            m.positions.push_back(c + Vec3f(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * r);
        }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segs; ++j) {
            const uint32_t a = base + uint32_t(i * (segs + 1) + j), b = a + uint32_t(segs + 1);
            for (uint32_t k : {a, b, a + 1, a + 1, b, b + 1}) m.indices.push_back(k);
        }
}

/// The material of every generated scene, for the recording render only (the accelerators read
/// geometry alone): Whitted's (1980) transparent surface, which both reflects and refracts, so
/// every hit spawns a reflection and a refraction ray (two incoherent rays per hit, as a mirror
/// next to a glass would), weights 0.25 and 0.7 so neither branch is cut before kBenchDepth by
/// the CLI's min-weight 1/255. Solid (not thin): rays inside the tessellated spheres refract
/// out again.
Material bench_glass() {
    Material m;
    m.name = "bench glass (mirror + glass)";
    m.model = MaterialModel::Classic;
    m.double_sided = true;
    m.classic.kd = Color(0.1f);
    m.classic.ka = Color(0.1f);
    m.classic.ks = Color(0.4f);
    m.classic.n = 40.f;
    m.classic.kr = Color(0.25f);
    m.classic.kt = Color(0.7f);
    m.classic.ior = 1.5f;
    m.classic.thin = false;
    return m;
}

/// Ray-tree depth of the recording render of a generated scene (camera ray = depth 0): up to
/// 2 + 4 + 8 secondary rays per camera hit. Scene files keep their own depth.
constexpr int kBenchDepth = 3;

/// Camera, point light and bench_glass() for a generated scene, so it can be rendered: the camera
/// looks at the origin from (0.6, 0.9, 3.2), vertical field of view 2 atan(0.45), square image.
void dress_for_render(Scene& s) {
    s.materials.push_back(bench_glass());
    Light light;
    light.name = "bench light";
    light.type = LightType::Point;
    light.position = Vec3d(-2, 3, 2);
    light.intensity = 15.f;  // about 1 W/m^2 on the scene, 3.6 away
    s.lights.push_back(light);
    const Vec3d eye{0.6, 0.9, 3.2};
    const Vec3d fwd = normalize(Vec3d(0, 0, 0) - eye), right = normalize(cross(fwd, Vec3d(0, 1, 0))), up = cross(right, fwd);
    Camera cam;
    cam.name = "bench camera";
    cam.yfov = 2.0 * std::atan(0.45);
    cam.aspect = 1.0;
    for (int r = 0; r < 3; ++r) {  // columns: +X = right, +Y = up, +Z = backwards (looks down -Z), origin
        cam.world_from_camera(r, 0) = right[r];
        cam.world_from_camera(r, 1) = up[r];
        cam.world_from_camera(r, 2) = -fwd[r];
        cam.world_from_camera(r, 3) = eye[r];
    }
    s.cameras.push_back(cam);
}

/// A single-mesh scene of about `n` triangles, inside [-1, 1]^3, dressed for the recording render.
Scene make_scene(const std::string& kind, long n) {
    Scene s;
    Mesh m;
    m.name = kind;
    if (kind == "spheres") {
        // k^3 spheres of about n / k^3 triangles each, k = 4.
        const int k = 4;
        const long per = std::max(32L, n / (k * k * k));
        const int segs = std::max(4, int(std::sqrt(double(per))));
        const int rings = std::max(2, int(per / (2 * segs)));
        for (int x = 0; x < k; ++x)
            for (int y = 0; y < k; ++y)
                for (int z = 0; z < k; ++z)
                    add_sphere(m, Vec3f(-0.75f + 0.5f * float(x), -0.75f + 0.5f * float(y), -0.75f + 0.5f * float(z)),
                               0.2f, rings, segs);
    } else if (kind == "soup") {
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> p(-1.f, 1.f);
        const float size = 2.f * std::cbrt(1.f / float(n)) * 1.5f;
        std::uniform_real_distribution<float> o(-size, size);
        for (long i = 0; i < n; ++i) {
            const Vec3f c{p(rng), p(rng), p(rng)};
            for (int v = 0; v < 3; ++v) {
                m.positions.push_back(c + Vec3f(o(rng), o(rng), o(rng)));
                m.indices.push_back(uint32_t(m.positions.size() - 1));
            }
        }
    } else if (kind == "terrain") {
        const int g = std::max(2, int(std::sqrt(double(n) / 2.0)));
        for (int y = 0; y <= g; ++y)
            for (int x = 0; x <= g; ++x) {
                const float u = -1.f + 2.f * float(x) / float(g), v = -1.f + 2.f * float(y) / float(g);
                m.positions.push_back({u, 0.25f * std::sin(5.f * u) * std::cos(4.f * v) + 0.05f * std::sin(31.f * u * v), v});
            }
        for (int y = 0; y < g; ++y)
            for (int x = 0; x < g; ++x) {
                const uint32_t a = uint32_t(y * (g + 1) + x), b = a + 1, c = a + uint32_t(g + 1), d = c + 1;
                for (uint32_t k : {a, d, b, a, c, d}) m.indices.push_back(k);
            }
    } else {
        throw Error(fmt::format("bench accel: unknown scene '{}' (available: spheres, soup, terrain)", kind));
    }
    // Shading normals for the recording render: smooth over the spheres and the terrain, the face
    // normal for the soup (no shared vertices).
    m.normals = smooth_normals(m);
    s.meshes.push_back(std::move(m));
    Instance inst;
    inst.mesh = 0;
    s.instances.push_back(inst);
    dress_for_render(s);
    return s;
}

/// A scene name with a file extension is a scene file (a real asset), resolved against the
/// working directory, then the source tree; other names are generators.
bool is_scene_file(const std::string& name) { return fs::path(name).has_extension(); }

Scene load_scene_file(const std::string& name) {
    const fs::path in_tree = fs::path(WHITTED_SOURCE_DIR) / name;
    return load_scene(fs::exists(name) || !fs::exists(in_tree) ? name : in_tree.string());
}

/// The label of a scene in tables and CSV: the generator's name or the file's stem.
std::string scene_label(const std::string& name) { return is_scene_file(name) ? fs::path(name).stem().string() : name; }

// ---- ray sets: recorded from a real render ----

/// The three ray kinds replayed, in this order everywhere (tables, CSV `kind`).
constexpr std::array<const char*, 3> kKinds{"camera", "shadow", "secondary"};

struct RaySets {
    std::array<std::vector<RecordedRay>, 3> sets;  ///< camera, shadow, secondary (reflection + refraction)
    std::array<size_t, 3> recorded{};              ///< rays of each kind the render traced (before thinning)
    int width = 0, height = 0;                     ///< the recording render's image
};

/// At most `cap` rays of `v`, evenly spaced, in recording order.
std::vector<RecordedRay> thin(const std::vector<RecordedRay>& v, size_t cap) {
    if (v.size() <= cap) return v;
    std::vector<RecordedRay> out;
    out.reserve(cap);
    for (size_t i = 0; i < cap; ++i) out.push_back(v[i * v.size() / cap]);
    return out;
}

/// Renders `scene` once with the Whitted integrator through a RecordingAccelerator around the
/// in-house `bvh` and returns its rays by kind: about `count` camera rays (one per pixel centre
/// of a square image, or `count` / aspect for a scene file's camera), and its shadow and
/// secondary rays thinned to at most `count` each. One thread, so the log follows the tiles in
/// the same order every run. The integrator uses the CLI's defaults (min-weight 1/255) and, for
/// generated scenes, depth kBenchDepth; scene files keep their settings except size and
/// anti-aliasing.
RaySets record_rays(const Scene& scene, bool generated, int count) {
    RenderSettings rs;
    rs.integrator.min_weight = 1.f / 255.f;  // the CLI's default (docs/integrator.md)
    apply_scene_settings(scene.settings, rs);
    if (generated) rs.integrator.max_depth = kBenchDepth;
    const int side = std::max(8, int(std::sqrt(double(count))));
    rs.width = side;
    rs.height = generated ? side : 0;  // a scene file's camera: height from its aspect ratio
    rs.aa = AaSettings{};              // one ray per pixel centre
    rs.threads = 1;
    rs.accel = "bvh";
    rs.progress = false;
    const Renderer renderer(scene, rs);
    const RecordingAccelerator recorder(renderer.accelerator());
    (void)renderer.render(rs.aa, rs.integrator, recorder);
    RaySets r;
    r.width = renderer.image_size().width;
    r.height = renderer.image_size().height;
    std::array<std::vector<RecordedRay>, 3> all;
    for (const RecordedRay& rr : recorder.rays())
        all[rr.shadow ? 1 : rr.kind == RayKind::Camera ? 0 : 2].push_back(rr);
    for (size_t k = 0; k < 3; ++k) {
        r.recorded[k] = all[k].size();
        r.sets[k] = k == 0 ? std::move(all[k]) : thin(all[k], size_t(count));
    }
    return r;
}

/// One query of a recorded ray, as the render made it: closest hit (the value is t) or
/// transmittance (the value is its red channel).
inline float trace(const Accelerator& accel, const RecordedRay& rr) {
    return rr.shadow ? accel.transmittance(rr.ray).x : accel.intersect(rr.ray, rr.kind).t;
}

// ---- validation against the oracle ----

/// The oracle's answers on an evenly spaced sample of every ray set, computed once per scene and
/// size; each backend is compared with them before its figures are trusted.
struct OracleAnswers {
    std::string name;                 ///< "brute", "bvh" or "bvh:width=2"
    std::vector<RecordedRay> rays;    ///< up to `per_set` rays of each kind
    std::vector<Hit> hits;            ///< closest hit (shadow rays too: where the segment is blocked)
    std::vector<float> transmittance; ///< shadow rays
    double near_origin = 0.0;         ///< distance from a ray's origin below which hits are ambiguous
};

/// `near_origin`: see validate().
OracleAnswers oracle_answers(const Accelerator& oracle, const std::string& name, const RaySets& rays, size_t per_set,
                             double near_origin) {
    OracleAnswers a;
    a.name = name;
    a.near_origin = near_origin;
    for (const std::vector<RecordedRay>& set : rays.sets) {
        const size_t stride = std::max<size_t>(1, set.size() / per_set);
        for (size_t i = 0; i < set.size(); i += stride) a.rays.push_back(set[i]);
    }
    a.hits.resize(a.rays.size());
    a.transmittance.resize(a.rays.size(), 1.f);
    // In parallel: brute force over 100k triangles costs about a millisecond per ray.
    tbb::parallel_for(size_t(0), a.rays.size(), [&](size_t i) {
        a.hits[i] = oracle.intersect(a.rays[i].ray, a.rays[i].kind);
        if (a.rays[i].shadow) a.transmittance[i] = oracle.transmittance(a.rays[i].ray).x;
    });
    return a;
}

struct Validation {
    double mismatch = 0.0;     ///< fraction of the sample answered differently
    double near_origin = 0.0;  ///< fraction left out: the answers differ by a hit next to the origin
};

/// Compares `accel` with the oracle on its sample. A ray is a mismatch when the answers differ:
/// hit vs miss, or another primitive at a t more than 1e-5 relative away (a different primitive
/// at the same t is a tie at a shared edge or vertex, either is right); for a shadow ray,
/// blocked vs not blocked (the bench's surfaces are opaque: transmittance 0 or 1). A difference
/// caused by a hit closer to the ray's origin than `near_origin` (1e-4 of the scene's diagonal,
/// the rule of the cross-check tests) is counted apart: the recorded secondary and shadow rays
/// start a few ulps off a surface, and whether that surface is hit again at t ~ 1e-8 is decided by
/// rounding (the float triangle test may report it, a conservative box test behind the origin may
/// cull it): the ray-offset problem, not a traversal error.
Validation validate(const Accelerator& accel, const OracleAnswers& oracle) {
    std::vector<uint8_t> verdict(oracle.rays.size(), 0);  // 0 same, 1 mismatch, 2 near the origin
    tbb::parallel_for(size_t(0), oracle.rays.size(), [&](size_t i) {
        const RecordedRay& rr = oracle.rays[i];
        const Hit& b = oracle.hits[i];
        const float len = length(rr.ray.dir);
        auto near = [&](const Hit& h) { return h.valid() && double(h.t) * double(len) < oracle.near_origin; };
        if (rr.shadow) {
            if ((accel.transmittance(rr.ray).x == 0.f) == (oracle.transmittance[i] == 0.f)) return;
            verdict[i] = near(b) || near(accel.intersect(rr.ray, rr.kind)) ? 2 : 1;
            return;
        }
        const Hit a = accel.intersect(rr.ray, rr.kind);
        const bool same_prim = a.prim == b.prim && a.geom == b.geom && a.inst == b.inst;
        if (a.valid() == b.valid() && (!a.valid() || same_prim || std::fabs(a.t - b.t) <= 1e-5f * b.t)) return;
        verdict[i] = near(a) || near(b) ? 2 : 1;
    });
    Validation v;
    if (oracle.rays.empty()) return v;
    v.mismatch = double(std::count(verdict.begin(), verdict.end(), uint8_t(1))) / double(oracle.rays.size());
    v.near_origin = double(std::count(verdict.begin(), verdict.end(), uint8_t(2))) / double(oracle.rays.size());
    return v;
}

/// "ok vs brute (0.0000%; 0.2% near the origin)" or "UNTRUSTED vs ...": a figure is trusted
/// when at most 0.1% of the sample is a mismatch.
std::string describe(const Validation& v, const std::string& oracle) {
    const std::string near = v.near_origin > 0 ? fmt::format("; {:.3f}% near the origin", 100 * v.near_origin) : "";
    return v.mismatch <= 1e-3 ? fmt::format("ok vs {} ({:.4f}%{})", oracle, 100 * v.mismatch, near)
                              : fmt::format("UNTRUSTED vs {} ({:.3f}% differ{})", oracle, 100 * v.mismatch, near);
}

/// 1e-4 of the diagonal of the scene's bounds (the near-origin rule of validate()).
double near_origin_distance(const Scene& scene) {
    const Bounds3d b = scene.world_bounds();
    const double d = b.empty() ? 0.0 : length(b.hi - b.lo);
    return std::isfinite(d) && d > 0 ? 1e-4 * d : 1e-4;
}

/// Mrays/s of one ray set on `threads` threads (the best of 3 runs). One thread traces on the
/// calling thread and is timed by its CPU time (time descheduled by other processes on a shared
/// machine does not count); more threads run over TBB and are timed by the wall clock. Slow
/// backends trace a prefix of the rays sized so the three runs take about `seconds`.
double throughput(const Accelerator& accel, const std::vector<RecordedRay>& rays, int threads, double seconds) {
    if (rays.empty()) return 0.0;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const bool cpu_clock = threads == 1;
    auto now = [&] {
        return cpu_clock ? thread_cpu_seconds() : std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    };
    // Probe the cost per ray on a small prefix: up to 512 rays, fewer once they take a tenth of
    // the time allowed (brute force over a million triangles takes ~10 ms per ray).
    const double probe = now();
    volatile float probe_sink = 0.f;
    size_t count = 0;
    while (count < std::min<size_t>(rays.size(), 512) && (count < 8 || now() - probe < 0.1 * seconds))
        probe_sink = probe_sink + trace(accel, rays[count++]);
    const double per_ray = (now() - probe) / double(count) / double(threads);
    count = std::clamp<size_t>(size_t(seconds / 3.0 / std::max(per_ray, 1e-12)), count, rays.size());
    double best = 1e30;
    for (int run = 0; run < 3; ++run) {
        const double t = now();
        if (cpu_clock) {
            volatile float sink = 0.f;
            for (size_t i = 0; i < count; ++i) sink = sink + trace(accel, rays[i]);
        } else {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& r) {
                volatile float sink = 0.f;
                for (size_t i = r.begin(); i != r.end(); ++i) sink = sink + trace(accel, rays[i]);
            });
        }
        best = std::min(best, now() - t);
    }
    return double(count) / best * 1e-6;
}

// ---- --ratio: one thread, backends interleaved, time per ray relative to the first ----

/// Nanoseconds per ray of one pass over `rays` on the calling thread (no task scheduler): the
/// fastest of at least `min_passes` passes and of as many as fit in about 0.15 s of thread CPU
/// time. The minimum is the figure least disturbed by other processes (they only add time).
double ns_per_ray(const Accelerator& accel, const std::vector<RecordedRay>& rays, int min_passes) {
    if (rays.empty()) return 0.0;
    double best = 1e30, total = 0.0;
    for (int p = 0; p < 1000 && (p < min_passes || total < 0.15); ++p) {
        volatile float sink = 0.f;
        const double t = thread_cpu_seconds();
        for (const RecordedRay& r : rays) sink = sink + trace(accel, r);
        const double dt = thread_cpu_seconds() - t;
        best = std::min(best, dt);
        total += dt;
    }
    return best * 1e9 / double(rays.size());
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return a.empty() ? "unknown" : a + " " + b + " " + c;
}

/// A CSV cell: quoted when it holds a comma (specs like "bvh:width=2,leaf=4").
std::string csv_cell(const std::string& s) { return s.find(',') == std::string::npos ? s : "\"" + s + "\""; }

/// The 1-minute load average alone (a CSV cell).
std::string load_1min() {
    const double l = load_average_1min();
    return l < 0 ? "unknown" : fmt::format("{:.2f}", l);
}

/// The sizes a scene name runs at: every --sizes value for a generator, once for a scene file.
std::vector<long> sizes_of(const std::string& name, const std::vector<long>& sizes) {
    return is_scene_file(name) ? std::vector<long>{0} : sizes;
}

Scene bench_scene(const std::string& name, long n) { return is_scene_file(name) ? load_scene_file(name) : make_scene(name, n); }

/// One line about the recording render: image size and rays recorded and replayed per kind.
void print_recording(const std::string& label, size_t tris, const RaySets& rays) {
    std::printf("%s, %zu triangles: recorded from a %dx%d render: camera %zu, shadow %zu (replayed %zu), secondary %zu "
                "(replayed %zu)\n",
                label.c_str(), tris, rays.width, rays.height, rays.recorded[0], rays.recorded[1], rays.sets[1].size(),
                rays.recorded[2], rays.sets[2].size());
}

/// For each scene and size: records the rays, builds every backend, validates it, then `repeats`
/// times measures every ray kind on one thread for each backend in turn (so all backends see the
/// same machine load), and reports the median time per ray and the median of the per-repetition
/// ratios to the first backend (Embree by default).
int run_ratio(const BenchAccelOptions& o) {
    fs::create_directories(o.out);
    const std::string csv_path = (fs::path(o.out) / "ratio.csv").string();
    std::ofstream csv(csv_path);
    csv << "scene,triangles,accel,kind,rays,ns_per_ray_median,ratio_median,ratio_min,ratio_max,repeats,load_before,load_after,"
           "validated_against,mismatch_fraction,near_origin_fraction\n";
    OpaqueFilter filter;
    for (const std::string& name : o.scenes) {
        for (long n : sizes_of(name, o.sizes)) {
            const Scene scene = bench_scene(name, n);
            const std::string label = scene_label(name);
            const size_t tris = scene.instanced_triangle_count();
            const RaySets rays = record_rays(scene, !is_scene_file(name), o.rays);
            print_recording(label, tris, rays);
            // The oracle: brute force where it is affordable, else the binary in-house tree.
            const std::string oracle_name = tris <= 100000 ? "brute" : "bvh:width=2";
            const OracleAnswers oracle = oracle_answers(*create_accelerator(oracle_name, scene, filter), oracle_name, rays, 1500,
                                                        near_origin_distance(scene));
            std::vector<std::unique_ptr<Accelerator>> accels;
            std::vector<Validation> mismatch;
            for (const std::string& spec : o.accels) {
                accels.push_back(create_accelerator(spec, scene, filter));
                mismatch.push_back(validate(*accels.back(), oracle));
            }
            // ns[accel][kind][repeat]
            std::vector<std::array<std::vector<double>, 3>> ns(accels.size());
            const std::string load_before = load_average();
            for (int rep = 0; rep < o.repeats; ++rep)
                for (size_t k = 0; k < 3; ++k)
                    for (size_t a = 0; a < accels.size(); ++a) ns[a][k].push_back(ns_per_ray(*accels[a], rays.sets[k], 3));
            const std::string load_after = load_average();
            std::printf("\n%s, %zu triangles, %zu/%zu/%zu rays, 1 thread, %d interleaved repeats, load %s -> %s\n",
                        label.c_str(), tris, rays.sets[0].size(), rays.sets[1].size(), rays.sets[2].size(), o.repeats,
                        load_before.c_str(), load_after.c_str());
            std::printf("  %-22s %10s %10s %10s   %-26s %-26s %-26s %s\n", "accel", "cam ns", "shd ns", "sec ns",
                        "cam ratio [min,max]", "shd ratio [min,max]", "sec ratio [min,max]", "validation");
            for (size_t a = 0; a < accels.size(); ++a) {
                std::string cells[3];
                double med[3];
                for (size_t k = 0; k < 3; ++k) {
                    std::vector<double> ratios;
                    for (int rep = 0; rep < o.repeats; ++rep) ratios.push_back(ns[a][k][size_t(rep)] / ns[0][k][size_t(rep)]);
                    med[k] = median(ns[a][k]);
                    const double r = median(ratios);
                    const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
                    cells[k] = fmt::format("{:.2f}x [{:.2f},{:.2f}]", r, *lo, *hi);
                    csv << fmt::format("{},{},{},{},{},{:.2f},{:.4f},{:.4f},{:.4f},{},{},{},{},{:.6f},{:.6f}\n", label, tris,
                                       csv_cell(o.accels[a]), kKinds[k], rays.sets[k].size(), med[k], r, *lo, *hi, o.repeats,
                                       load_before, load_after, oracle.name, mismatch[a].mismatch, mismatch[a].near_origin);
                }
                const std::string valid = describe(mismatch[a], oracle.name);
                std::printf("  %-22s %10.1f %10.1f %10.1f   %-26s %-26s %-26s %s\n", o.accels[a].c_str(), med[0], med[1],
                            med[2], cells[0].c_str(), cells[1].c_str(), cells[2].c_str(), valid.c_str());
                std::fflush(stdout);
            }
        }
    }
    std::printf("wrote %s\n", csv_path.c_str());
    return 0;
}

/// --accel is split at commas, which also separate a spec's options: a piece "key=value" without
/// a backend name continues the spec before it ("bvh:leaf=16", "bins=32" -> "bvh:leaf=16,bins=32").
std::vector<std::string> join_spec_options(const std::vector<std::string>& pieces) {
    std::vector<std::string> specs;
    for (const std::string& p : pieces) {
        const bool option = p.find('=') != std::string::npos && p.find(':') == std::string::npos;
        if (option && !specs.empty()) specs.back() += "," + p;
        else specs.push_back(p);
    }
    return specs;
}

int run(BenchAccelOptions o) {
    o.accels = join_spec_options(o.accels);
    if (o.ratio) return run_ratio(o);
    fs::create_directories(o.out);
    const std::string csv_path = (fs::path(o.out) / "accel.csv").string();
    std::ofstream csv(csv_path);
    csv << "scene,triangles,accel,build_s,bytes_per_tri,nodes,sah,threads,camera_rays,shadow_rays,secondary_rays,"
           "camera_mrays,shadow_mrays,secondary_mrays,validated_against,mismatch_fraction,near_origin_fraction,load\n";
    std::printf("%-8s %9s %-8s %9s %8s %9s %8s %3s %9s %9s %9s %s\n", "scene", "tris", "accel", "build_s", "B/tri",
                "nodes", "SAH", "thr", "cam_Mr/s", "shd_Mr/s", "sec_Mr/s", "validation");
    OpaqueFilter filter;
    std::vector<std::string> skipped;
    auto skip = [&](const std::string& why) {
        std::printf("skipped: %s\n", why.c_str());
        std::fflush(stdout);
        skipped.push_back(why);
    };
    for (const std::string& name : o.scenes) {
        // Build seconds and size of each backend's last measured cell, to predict whether the
        // next build fits the budget (tracing is capped to its share of the budget by throughput()).
        std::map<std::string, std::pair<double, size_t>> last_build;
        for (long n : sizes_of(name, o.sizes)) {
            const Scene scene = bench_scene(name, n);
            const std::string label = scene_label(name);
            const size_t tris = scene.instanced_triangle_count();
            // The backends this cell runs: above 1.5M triangles embree and bvh only, and none whose
            // build is predicted past the budget.
            std::vector<std::pair<std::string, std::string>> cells;  // (name as given, spec built)
            for (const std::string& accel : o.accels) {
                std::string spec = accel;
                if (accel == "bvh" && (o.precision != "float" || o.bv != "aabb"))
                    spec = fmt::format("bvh:precision={},bv={}", o.precision, o.bv);
                const std::string base = accel.substr(0, accel.find(':'));
                if (tris > 1500000 && base != "embree" && base != "bvh") {
                    skip(fmt::format("{} {} {}: > 1.5M triangles run for embree and bvh only", label, tris, accel));
                    continue;
                }
                // Predict this cell's time from the previous size (O(n) growth as the worst case).
                if (last_build.count(accel)) {
                    const auto [seconds, at] = last_build[accel];
                    const double predicted = seconds * double(tris) / double(at) * 1.3;  // ~ n log n
                    if (predicted > o.budget) {
                        skip(fmt::format("{} {} {}: predicted build {:.3g} s > budget {:.3g} s", label, tris, accel,
                                         predicted, o.budget));
                        continue;
                    }
                }
                cells.emplace_back(accel, spec);
            }
            if (cells.empty()) continue;
            const RaySets rays = record_rays(scene, !is_scene_file(name), o.rays);
            print_recording(label, tris, rays);
            // The oracle: brute force up to 100k triangles, else `bvh` (itself checked against
            // brute force here at the smaller sizes and in the cross-check tests). A `bvh` cell
            // with the same spec is measured on the oracle's structure instead of a second build.
            const std::string oracle_name = tris <= 100000 ? "brute" : "bvh";
            std::unique_ptr<Accelerator> oracle_accel = create_accelerator(oracle_name, scene, filter);
            const OracleAnswers oracle = oracle_answers(*oracle_accel, oracle_name, rays, 1500, near_origin_distance(scene));
            if (oracle_name == "brute") oracle_accel.reset();
            for (const auto& [accel_name, spec] : cells) {
                std::unique_ptr<Accelerator> own;
                const Accelerator* accel = oracle_accel && spec == oracle_name ? oracle_accel.get() : nullptr;
                if (!accel) {
                    own = create_accelerator(spec, scene, filter);
                    accel = own.get();
                }
                const AccelStats st = accel->stats();
                const Validation v = validate(*accel, oracle);
                last_build[accel_name] = {st.build_seconds, tris};
                const double per_tri = double(st.bytes) / double(std::max<size_t>(1, tris));
                const std::string valid = describe(v, oracle.name);
                for (int threads : o.threads) {
                    const double slice = o.budget / double(3 * o.threads.size() + 1);
                    std::array<double, 3> mrays{};
                    for (size_t k = 0; k < 3; ++k) mrays[k] = throughput(*accel, rays.sets[k], threads, slice);
                    std::printf("%-8s %9zu %-8s %9.4f %8.1f %9zu %8.2f %3d %9.4g %9.4g %9.4g %s\n", label.c_str(), tris,
                                spec.c_str(), st.build_seconds, per_tri, st.nodes, st.sah_cost, threads, mrays[0],
                                mrays[1], mrays[2], valid.c_str());
                    std::fflush(stdout);
                    csv << fmt::format("{},{},{},{:.6f},{:.2f},{},{:.4f},{},{},{},{},{:.6g},{:.6g},{:.6g},{},{:.6f},{:.6f},{}\n",
                                       label, tris, csv_cell(spec), st.build_seconds, per_tri, st.nodes, st.sah_cost, threads,
                                       rays.sets[0].size(), rays.sets[1].size(), rays.sets[2].size(), mrays[0], mrays[1],
                                       mrays[2], oracle.name, v.mismatch, v.near_origin, load_1min());
                }
            }
        }
    }
    csv.close();
    if (!skipped.empty()) std::printf("%zu cells skipped (listed above)\n", skipped.size());
    std::printf("wrote %s\n", csv_path.c_str());
    // The plot: time per ray against triangle count, log-log (needs python3-matplotlib).
    const std::string script = std::string(WHITTED_SOURCE_DIR) + "/scripts/plot_accel.py";
    // Debian's interpreter (where python3-matplotlib installs), not whatever python3 is first on PATH.
    const std::string python = default_python();
    const std::string cmd = fmt::format("{} '{}' '{}' '{}' 2>&1", python, script, csv_path, (fs::path(o.out) / "accel.png").string());
    if (std::system(cmd.c_str()) != 0)
        log_warning("bench accel: no plot (needs python3-matplotlib and a scene at two sizes; then run: python3 "
                    "scripts/plot_accel.py {} accel.png)",
                    csv_path);
    return 0;
}

}  // namespace

Command register_bench_accel(CLI::App& bench) {
    auto o = std::make_shared<BenchAccelOptions>();
    CLI::App* app = bench.add_subcommand("accel", "Accelerators: build time, memory, Mrays/s (docs/accelerators.md)");
    app->add_option("--accel", o->accels, "Backends to measure (names or specs like grid:lambda=8 or bvh:width=2,leaf=4)")->delimiter(',')
        ->capture_default_str();
    app->add_option("--scenes", o->scenes, "Procedural scenes (spheres, soup, terrain) and scene files (.glb, .gltf, .json)")
        ->delimiter(',')
        ->capture_default_str();
    app->add_option("--sizes", o->sizes, "Triangle counts")->delimiter(',')->capture_default_str();
    app->add_option("--threads", o->threads, "Thread counts to trace with")->delimiter(',')->capture_default_str();
    app->add_option("--rays", o->rays,
                    "Camera rays of the recording render (its shadow and secondary rays are thinned to at most as many)")
        ->check(CLI::Range(64, 1 << 24))->capture_default_str();
    app->add_option("--budget", o->budget, "Seconds per cell; cells predicted to take longer are skipped")
        ->capture_default_str();
    app->add_option("--precision", o->precision, "Precision of the in-house bvh: float or double")
        ->check(CLI::IsMember({"float", "double"}))->capture_default_str();
    app->add_option("--bv", o->bv, "Bounding volume of the in-house bvh nodes: aabb or sphere")
        ->check(CLI::IsMember({"aabb", "sphere"}))->capture_default_str();
    app->add_option("-o,--out", o->out, "Output directory for accel.csv and accel.png")->capture_default_str();
    app->add_flag("--ratio", o->ratio,
                  "One thread, backends interleaved: time per ray and its ratio to the first --accel "
                  "(writes ratio.csv)");
    app->add_option("--repeats", o->repeats, "Interleaved repetitions for --ratio (median reported)")
        ->check(CLI::Range(1, 100))->capture_default_str();
    return {app, [o] { return run(*o); }};
}

}  // namespace whitted::app
