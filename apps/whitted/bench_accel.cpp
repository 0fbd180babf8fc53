// `whitted bench accel`: build time, memory and ray throughput of every accelerator on procedural
// scenes of growing size (docs/accelerators.md).
//
// Scenes (our own generators): `spheres` (tessellated spheres on a grid), `soup` (random
// triangles), `terrain` (a height field), each at 1k, 10k, 100k, 1M and 5M triangles (5M for
// embree and bvh only). Per backend and size: build time, bytes per triangle, nodes, SAH cost,
// and Mrays/s for coherent camera rays (row by row from a pinhole camera), shadow rays (from the
// camera hits to a point light) and incoherent rays (secondary rays from the camera hits in
// uniformly random directions, replayed from a recorded list), on 1 and 2 threads. Before a
// figure is printed the backend's hits are validated against `brute` (<= 100k triangles) or
// `bvh` on a few thousand rays. Each cell has a time budget; cells expected to exceed it are
// skipped and listed. Writes CSV and, when python3-matplotlib is installed, a log-log PNG via
// scripts/plot_accel.py.
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

#include "apps/whitted/command.h"
#include "renderer/accel/accelerator.h"
#include "renderer/core/error.h"
#include "renderer/core/log.h"
#include "renderer/scene/scene.h"

namespace whitted::app {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct BenchAccelOptions {
    std::vector<std::string> accels{"embree", "bvh", "grid", "octree", "kdop", "brute"};
    std::vector<std::string> scenes{"spheres", "soup", "terrain"};
    std::vector<long> sizes{1000, 10000, 100000, 1000000, 5000000};
    std::vector<int> threads{1, 2};
    int rays = 1 << 18;             ///< rays per query kind and run (a 512x512 camera)
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

/// A single-mesh scene of about `n` triangles, inside [-1, 1]^3.
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
    m.normals.assign(m.positions.size(), Vec3f(0, 1, 0));
    s.meshes.push_back(std::move(m));
    Instance inst;
    inst.mesh = 0;
    s.instances.push_back(inst);
    return s;
}

// ---- ray sets ----

struct RaySets {
    std::vector<Ray> camera, shadow, incoherent;
};

/// Camera rays row by row over a square image looking at the scene from (0.6, 0.9, 3.2); shadow
/// and incoherent rays from the camera hits (recorded with `reference`, then replayed).
RaySets make_rays(const Accelerator& reference, int count) {
    RaySets r;
    const int side = std::max(8, int(std::sqrt(double(count))));
    const Vec3f eye{0.6f, 0.9f, 3.2f}, light{-2.f, 3.f, 2.f};
    const Vec3f fwd = normalize(Vec3f(0, 0, 0) - eye), right = normalize(cross(fwd, Vec3f(0, 1, 0))),
                up = cross(right, fwd);
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            const float u = (float(x) + 0.5f) / float(side) * 2.f - 1.f, v = 1.f - (float(y) + 0.5f) / float(side) * 2.f;
            Ray ray;
            ray.org = eye;
            ray.dir = normalize(fwd + right * (0.45f * u) + up * (0.45f * v));
            r.camera.push_back(ray);
        }
    std::vector<Hit> hits(r.camera.size());
    tbb::parallel_for(size_t(0), r.camera.size(), [&](size_t i) { hits[i] = reference.intersect(r.camera[i], RayKind::Camera); });
    std::mt19937 rng(5);
    std::normal_distribution<float> g;
    for (size_t i = 0; i < hits.size(); ++i) {
        if (!hits[i].valid()) continue;
        const Vec3f p = r.camera[i].org + r.camera[i].dir * hits[i].t;
        Ray s;
        s.org = p;
        s.dir = light - p;
        s.tnear = 1e-4f;
        s.tfar = 1.f;
        r.shadow.push_back(s);
        Ray b;
        b.org = p;
        b.dir = normalize(Vec3f(g(rng), g(rng), g(rng)));
        b.tnear = 1e-4f;
        r.incoherent.push_back(b);
    }
    return r;
}

/// Hits of `accel` against `oracle` on up to `n` rays of each set: the fraction that differ
/// (other primitive at a t more than 1e-5 relative away, or hit vs miss).
double validate(const Accelerator& accel, const Accelerator& oracle, const RaySets& rays, size_t n) {
    size_t bad = 0, total = 0;
    for (const std::vector<Ray>* set : {&rays.camera, &rays.incoherent}) {
        const size_t stride = std::max<size_t>(1, set->size() / n);
        for (size_t i = 0; i < set->size(); i += stride) {
            const Hit a = accel.intersect((*set)[i], RayKind::Camera), b = oracle.intersect((*set)[i], RayKind::Camera);
            ++total;
            if (a.valid() != b.valid()) ++bad;
            else if (a.valid() && a.prim != b.prim && std::fabs(a.t - b.t) > 1e-5f * b.t) ++bad;
        }
    }
    return total ? double(bad) / double(total) : 0.0;
}

/// Mrays/s of one query kind on `threads` threads (the best of 3 runs). Slow backends trace a
/// prefix of the rays sized so the three runs take about `seconds`.
double throughput(const Accelerator& accel, const std::vector<Ray>& rays, bool shadow, int threads, double seconds) {
    if (rays.empty()) return 0.0;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    auto trace = [&](size_t i) { return shadow ? accel.transmittance(rays[i]).x : accel.intersect(rays[i], RayKind::Camera).t; };
    // Probe the cost per ray on a small prefix.
    size_t count = std::min<size_t>(rays.size(), 512);
    const auto probe = Clock::now();
    volatile float probe_sink = 0.f;
    for (size_t i = 0; i < count; ++i) probe_sink = probe_sink + trace(i);
    const double per_ray = seconds_since(probe) / double(count) / double(threads);
    count = std::clamp<size_t>(size_t(seconds / 3.0 / std::max(per_ray, 1e-12)), count, rays.size());
    double best = 1e30;
    for (int run = 0; run < 3; ++run) {
        const auto t = Clock::now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& r) {
            volatile float sink = 0.f;
            for (size_t i = r.begin(); i != r.end(); ++i) sink = sink + trace(i);
        });
        best = std::min(best, seconds_since(t));
    }
    return double(count) / best * 1e-6;
}

// ---- --ratio: one thread, backends interleaved, time per ray relative to the first ----

/// CPU time of the calling thread: time the thread was descheduled (other processes on a
/// loaded machine) does not count.
double thread_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Nanoseconds per ray of one pass over `rays` on the calling thread (no task scheduler): the
/// fastest of at least `min_passes` passes and of as many as fit in about 0.15 s of thread CPU
/// time. The minimum is the figure least disturbed by other processes (they only add time).
double ns_per_ray(const Accelerator& accel, const std::vector<Ray>& rays, bool shadow, int min_passes) {
    if (rays.empty()) return 0.0;
    double best = 1e30, total = 0.0;
    for (int p = 0; p < 1000 && (p < min_passes || total < 0.15); ++p) {
        volatile float sink = 0.f;
        const double t = thread_seconds();
        if (shadow)
            for (const Ray& r : rays) sink = sink + accel.transmittance(r).x;
        else
            for (const Ray& r : rays) sink = sink + accel.intersect(r, RayKind::Camera).t;
        const double dt = thread_seconds() - t;
        best = std::min(best, dt);
        total += dt;
    }
    return best * 1e9 / double(rays.size());
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return a.empty() ? "unknown" : a + " " + b + " " + c;
}

/// For each scene and size: builds every backend, validates it, then `repeats` times measures
/// every ray kind on one thread for each backend in turn (so all backends see the same machine
/// load), and reports the median time per ray and the median of the per-repetition ratios to the
/// first backend (Embree by default).
int run_ratio(const BenchAccelOptions& o) {
    namespace fs = std::filesystem;
    fs::create_directories(o.out);
    const std::string csv_path = (fs::path(o.out) / "ratio.csv").string();
    std::ofstream csv(csv_path);
    csv << "scene,triangles,accel,kind,ns_per_ray_median,ratio_median,ratio_min,ratio_max,repeats,load_before,load_after,"
           "validated_against,mismatch_fraction\n";
    OpaqueFilter filter;
    const char* kinds[3] = {"camera", "shadow", "incoherent"};
    for (const std::string& kind : o.scenes) {
        for (long n : o.sizes) {
            const Scene scene = make_scene(kind, n);
            const size_t tris = scene.instanced_triangle_count();
            const auto reference = create_accelerator("bvh:width=2", scene, filter);
            const RaySets rays = make_rays(*reference, o.rays);
            std::unique_ptr<Accelerator> brute;
            if (tris <= 100000) brute = create_accelerator("brute", scene, filter);
            const Accelerator& oracle = brute ? *brute : *reference;
            std::vector<std::unique_ptr<Accelerator>> accels;
            std::vector<double> mismatch;
            for (const std::string& name : o.accels) {
                accels.push_back(create_accelerator(name, scene, filter));
                mismatch.push_back(validate(*accels.back(), oracle, rays, 1500));
            }
            const std::vector<Ray>* sets[3] = {&rays.camera, &rays.shadow, &rays.incoherent};
            // ns[accel][kind][repeat]
            std::vector<std::array<std::vector<double>, 3>> ns(accels.size());
            const std::string load_before = load_average();
            for (int rep = 0; rep < o.repeats; ++rep)
                for (int k = 0; k < 3; ++k)
                    for (size_t a = 0; a < accels.size(); ++a)
                        ns[a][k].push_back(ns_per_ray(*accels[a], *sets[k], k == 1, 3));
            const std::string load_after = load_average();
            std::printf("\n%s, %zu triangles, %zu/%zu/%zu rays, 1 thread, %d interleaved repeats, load %s -> %s\n",
                        kind.c_str(), tris, rays.camera.size(), rays.shadow.size(), rays.incoherent.size(), o.repeats,
                        load_before.c_str(), load_after.c_str());
            std::printf("  %-22s %10s %10s %10s   %-26s %-26s %-26s %s\n", "accel", "cam ns", "shd ns", "inc ns",
                        "cam ratio [min,max]", "shd ratio [min,max]", "inc ratio [min,max]", "validation");
            for (size_t a = 0; a < accels.size(); ++a) {
                std::string cells[3];
                double med[3];
                for (int k = 0; k < 3; ++k) {
                    std::vector<double> ratios;
                    for (int rep = 0; rep < o.repeats; ++rep) ratios.push_back(ns[a][k][size_t(rep)] / ns[0][k][size_t(rep)]);
                    med[k] = median(ns[a][k]);
                    const double r = median(ratios);
                    const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
                    cells[k] = fmt::format("{:.2f}x [{:.2f},{:.2f}]", r, *lo, *hi);
                    csv << fmt::format("{},{},{},{},{:.2f},{:.4f},{:.4f},{:.4f},{},{},{},{},{:.6f}\n", kind, tris,
                                       o.accels[a], kinds[k], med[k], r, *lo, *hi, o.repeats, load_before, load_after,
                                       brute ? "brute" : "bvh:width=2", mismatch[a]);
                }
                std::printf("  %-22s %10.1f %10.1f %10.1f   %-26s %-26s %-26s %s\n", o.accels[a].c_str(), med[0], med[1],
                            med[2], cells[0].c_str(), cells[1].c_str(), cells[2].c_str(),
                            mismatch[a] <= 1e-3 ? fmt::format("ok ({:.4f}%)", 100 * mismatch[a]).c_str()
                                                : fmt::format("UNTRUSTED ({:.3f}%)", 100 * mismatch[a]).c_str());
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
    namespace fs = std::filesystem;
    fs::create_directories(o.out);
    const std::string csv_path = (fs::path(o.out) / "accel.csv").string();
    std::ofstream csv(csv_path);
    csv << "scene,triangles,accel,build_s,bytes_per_tri,nodes,sah,threads,camera_mrays,shadow_mrays,incoherent_mrays,"
           "validated_against,mismatch_fraction\n";
    std::printf("%-8s %9s %-8s %9s %8s %9s %8s %3s %9s %9s %9s %s\n", "scene", "tris", "accel", "build_s", "B/tri",
                "nodes", "SAH", "thr", "cam_Mr/s", "shd_Mr/s", "inc_Mr/s", "validation");
    OpaqueFilter filter;
    std::vector<std::string> skipped;
    for (const std::string& kind : o.scenes) {
        // Build seconds and size of each backend's last measured cell, to predict whether the
        // next build fits the budget (tracing is capped to its share of the budget by throughput()).
        std::map<std::string, std::pair<double, size_t>> last_build;
        for (long n : o.sizes) {
            const Scene scene = make_scene(kind, n);
            const size_t tris = scene.instanced_triangle_count();
            const auto bvh_ref = create_accelerator("bvh", scene, filter);
            const RaySets rays = make_rays(*bvh_ref, o.rays);
            std::unique_ptr<Accelerator> brute;
            if (tris <= 100000) brute = create_accelerator("brute", scene, filter);
            for (const std::string& name : o.accels) {
                std::string spec = name;
                if (name == "bvh" && (o.precision != "float" || o.bv != "aabb"))
                    spec = fmt::format("bvh:precision={},bv={}", o.precision, o.bv);
                const std::string base = name.substr(0, name.find(':'));
                if (tris > 1500000 && base != "embree" && base != "bvh") {
                    skipped.push_back(fmt::format("{} {} {}: > 1.5M triangles run for embree and bvh only", kind, tris, name));
                    continue;
                }
                // Predict this cell's time from the previous size (O(n) growth as the worst case).
                if (last_build.count(name)) {
                    const auto [seconds, at] = last_build[name];
                    const double predicted = seconds * double(tris) / double(at) * 1.3;  // ~ n log n
                    if (predicted > o.budget) {
                        skipped.push_back(fmt::format("{} {} {}: predicted build {:.0f} s > budget {:.0f} s", kind, tris, name,
                                                      predicted, o.budget));
                        continue;
                    }
                }
                const auto accel = create_accelerator(spec, scene, filter);
                const AccelStats st = accel->stats();
                const Accelerator& oracle = brute ? *brute : *bvh_ref;
                const double mismatch = validate(*accel, oracle, rays, 1500);
                last_build[name] = {st.build_seconds, tris};
                const char* against = brute ? "brute" : "bvh";
                for (int threads : o.threads) {
                    const double slice = o.budget / double(3 * o.threads.size() + 1);
                    const double cam = throughput(*accel, rays.camera, false, threads, slice);
                    const double shd = throughput(*accel, rays.shadow, true, threads, slice);
                    const double inc = throughput(*accel, rays.incoherent, false, threads, slice);
                    const std::string valid = mismatch <= 1e-3 ? fmt::format("ok vs {} ({:.4f}%)", against, 100 * mismatch)
                                                               : fmt::format("UNTRUSTED vs {} ({:.3f}% differ)", against, 100 * mismatch);
                    std::printf("%-8s %9zu %-8s %9.4f %8.1f %9zu %8.2f %3d %9.3f %9.3f %9.3f %s\n", kind.c_str(), tris,
                                name.c_str(), st.build_seconds, double(st.bytes) / double(tris), st.nodes, st.sah_cost,
                                threads, cam, shd, inc, valid.c_str());
                    std::fflush(stdout);
                    csv << fmt::format("{},{},{},{:.6f},{:.2f},{},{:.4f},{},{:.4f},{:.4f},{:.4f},{},{:.6f}\n", kind, tris, name,
                                       st.build_seconds, double(st.bytes) / double(tris), st.nodes, st.sah_cost, threads,
                                       cam, shd, inc, against, mismatch);
                }
            }
        }
    }
    csv.close();
    for (const std::string& s : skipped) std::printf("skipped: %s\n", s.c_str());
    std::printf("wrote %s\n", csv_path.c_str());
    // The plot: time per ray against triangle count, log-log (needs python3-matplotlib).
    const std::string script = std::string(WHITTED_SOURCE_DIR) + "/scripts/plot_accel.py";
    // Debian's interpreter (where python3-matplotlib installs), not whatever python3 is first on PATH.
    const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string cmd = fmt::format("{} '{}' '{}' '{}' 2>&1", python, script, csv_path, (fs::path(o.out) / "accel.png").string());
    if (std::system(cmd.c_str()) != 0)
        log_warning("bench accel: no plot (install python3-matplotlib, then run: python3 scripts/plot_accel.py {})", csv_path);
    return 0;
}

}  // namespace

Command register_bench_accel(CLI::App& bench) {
    auto o = std::make_shared<BenchAccelOptions>();
    CLI::App* app = bench.add_subcommand("accel", "Accelerators: build time, memory, Mrays/s (docs/accelerators.md)");
    app->add_option("--accel", o->accels, "Backends to measure (names or specs like grid:lambda=8 or bvh:width=2,leaf=4)")->delimiter(',')
        ->capture_default_str();
    app->add_option("--scenes", o->scenes, "Procedural scenes: spheres, soup, terrain")->delimiter(',')->capture_default_str();
    app->add_option("--sizes", o->sizes, "Triangle counts")->delimiter(',')->capture_default_str();
    app->add_option("--threads", o->threads, "Thread counts to trace with")->delimiter(',')->capture_default_str();
    app->add_option("--rays", o->rays, "Camera rays per run (shadow and incoherent rays: one per camera hit)")
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
