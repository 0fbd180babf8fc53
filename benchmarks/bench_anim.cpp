// `whitted bench anim`: the cost of a frame of an animated scene (docs/performance.md,
// "whitted bench anim"), as `whitted render --frames` pays it.
//
// Two scenes: CesiumMan (assets/gltf/CesiumMan) and a generated skinned tube of about
// --triangles triangles (generated_skin.h). Each is loaded once with load_animated_scene (every
// animation looping, so each frame is a new pose) and its default camera is fixed to frame the
// bounds of every frame, as the CLI does. Then for each accelerator of --accel:
//  - a Renderer is built and frame 0 rendered at --width x --height (the render time);
//  - frames 1 .. N-1 at k / --fps seconds: SceneAnimator::pose and Renderer::update timed apart
//    and together (median and max over the frames), and whether the update was a refit;
//  - at --rebuild-frames of those frames, what a frame costs without the animator: load_scene at
//    that time plus a new Renderer, and a new Renderer alone on the posed scene (its accelerator's
//    own build time too); the updated accelerator is checked against that new one on rays aimed
//    at the deforming meshes (hits must agree);
//  - the per-frame update (pose + update, median) against the render time: target <= 10 %.
// Then the sequence: CesiumMan over --sequence-frames frames at --sequence-width x
// --sequence-height, timed from the load to the last frame rendered (load, camera bounds, build,
// and per frame pose + update + render; no image is written), against the sum of the frames'
// render times alone: target <= 1.2x.
//
// Wall-clock times on --threads workers (0: all cores). Prints a table and writes
// <out>/anim.csv (a row per scene and accelerator), <out>/anim_frames.csv (a row per updated
// frame) and <out>/anim_sequence.csv (a row per accelerator).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_timing.h"
#include "benchmarks/generated_skin.h"
#include "core/error.h"
#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"
#include "session/sequence.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kUpdateTarget = 0.10;   ///< per-frame update / 1080p render time
constexpr double kSequenceTarget = 1.2;  ///< sequence wall time / sum of its render times

struct BenchAnimOptions {
    std::vector<std::string> accels{"embree", "bvh"};         ///< accelerators, each measured on its own
    std::vector<std::string> scenes{"cesium", "generated"};  ///< which of the two scenes
    size_t triangles = 1000000;  ///< generated tube: about this many triangles
    int joints = 12;             ///< generated tube: joints in its chain
    int frames = 24;             ///< generated tube: frames measured (frame 0 is the load)
    int cesium_frames = 100;     ///< CesiumMan: frames measured
    double fps = 24.0;           ///< frame k is at k / fps seconds
    int width = 1920;            ///< render size of the update/render ratio, pixels
    int height = 1080;
    int rebuild_frames = 5;      ///< frames (evenly spread) at which a full rebuild is timed and checked
    int check_rays = 4096;       ///< rays comparing the updated accelerator with a new one per rebuild frame
    int sequence_frames = 100;   ///< CesiumMan sequence length (0: no sequence)
    int sequence_width = 640;    ///< sequence render size, pixels
    int sequence_height = 360;
    int threads = 0;             ///< render threads (0 = all cores)
    std::string out = "bench-anim";
    bool keep = false;           ///< keep the generated .glb in --out
};

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string cesium_path() {
    return (fs::path(WHITTED_SOURCE_DIR) / "assets" / "gltf" / "CesiumMan" / "glTF-Binary" / "CesiumMan.glb").string();
}

/// The settings `whitted render` starts from, with the bench's size, accelerator and threads.
RenderSettings anim_settings(const Scene& scene, const std::string& accel, int width, int height, int threads) {
    RenderSettings rs = command_line_render_settings();
    apply_scene_settings(scene.settings, rs);
    rs.width = width;
    rs.height = height;
    rs.accel = accel;
    rs.threads = threads;
    rs.progress = false;
    return rs;
}

ImportOptions anim_import(double time) {
    ImportOptions io;
    io.time = time;
    io.loop = true;  // every frame a new pose: a held last key would make later frames cheap to render, not to update
    return io;
}

/// The fixed camera of a sequence (as `render --frames`): when camera 0 is the default one, a
/// default camera framing the bounds of frames 0 .. frames-1; the scene is left posed at frame 0.
std::optional<Camera> sequence_camera(Scene& scene, SceneAnimator& animator, int frames, double fps) {
    if (scene.cameras.empty() || !scene.cameras[0].is_default) return std::nullopt;
    Camera c = default_camera(sequence_bounds(scene, animator, FrameRange{0, frames - 1, fps}));
    scene.cameras[0] = c;
    return c;
}

/// Rays aimed at random triangle centroids of the deforming meshes (every mesh when none deforms)
/// from outside the scene's bounds; returns how many `a` and `b` answer differently (hit or miss,
/// or a t differing by more than 1e-4 relative).
size_t compare_hits(const Accelerator& a, const Accelerator& b, const Scene& scene, int count, uint32_t seed) {
    std::vector<uint32_t> targets;
    for (size_t i = 0; i < scene.instances.size(); ++i)
        if (scene.meshes[scene.instances[i].mesh].deforming) targets.push_back(uint32_t(i));
    if (targets.empty())
        for (size_t i = 0; i < scene.instances.size(); ++i) targets.push_back(uint32_t(i));
    if (targets.empty()) return 0;
    const Bounds3d bounds = scene.world_bounds();
    const double radius = std::max(1e-6, length(bounds.diagonal()));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    size_t mismatches = 0;
    for (int r = 0; r < count; ++r) {
        const Instance& inst = scene.instances[targets[size_t(rng() % targets.size())]];
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (mesh.triangle_count() == 0) continue;
        const size_t t = size_t(rng() % mesh.triangle_count());
        const Vec3d centroid = (Vec3d(mesh.positions[mesh.indices[3 * t]]) + Vec3d(mesh.positions[mesh.indices[3 * t + 1]]) +
                                Vec3d(mesh.positions[mesh.indices[3 * t + 2]])) * (1.0 / 3.0);
        const Vec3d target = inst.world_from_object.apply_point(centroid);
        // An origin on a sphere around the bounds, uniformly distributed.
        const double z = 2.0 * u01(rng) - 1.0, phi = 2.0 * 3.14159265358979323846 * u01(rng);
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Vec3d origin = bounds.center() + Vec3d(s * std::cos(phi), z, s * std::sin(phi)) * (2.0 * radius);
        Ray ray;
        ray.org = Vec3f(origin);
        ray.dir = Vec3f(target - origin);
        const Hit ha = a.intersect(ray, RayKind::Reflection), hb = b.intersect(ray, RayKind::Reflection);
        if (ha.valid() != hb.valid() || (ha.valid() && std::abs(ha.t - hb.t) > 1e-4f * std::max(ha.t, hb.t))) ++mismatches;
    }
    return mismatches;
}

/// The frames 1 .. frames-1 at which the full rebuild is timed: `count` of them, evenly spread,
/// the last frame included.
std::set<int> rebuild_set(int frames, int count) {
    std::set<int> out;
    if (frames < 2 || count <= 0) return out;
    for (int i = 0; i < count; ++i)
        out.insert(count == 1 ? frames - 1 : 1 + int(std::lround(double(i) * double(frames - 2) / double(count - 1))));
    return out;
}

/// A scene the bench measures: loaded once, shared by the accelerators.
struct AnimScene {
    std::string label, path;
    int frames = 0;
    AnimatedScene loaded;
    std::optional<Camera> camera;  ///< the fixed default camera, if the file has none
    double load_seconds = 0.0;
    size_t triangles = 0;          ///< instanced
    size_t deforming_vertices = 0;
    size_t deforming_meshes = 0;
};

/// What one scene and accelerator measured.
struct AnimRow {
    std::string accel;
    double build = 0.0, render = 0.0;
    std::vector<double> pose, update, frame;
    size_t refit = 0, updated = 0;
    std::vector<double> rebuild_full, rebuild_renderer, rebuild_accel;
    size_t check_rays = 0, check_mismatches = 0;

    std::string accel_update() const { return refit == updated ? "refit" : refit == 0 ? "rebuilt" : "mixed"; }
    double ratio() const { return render > 0.0 ? median(frame) / render : 0.0; }
};

double max_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

AnimRow measure(AnimScene& s, const std::string& accel, const BenchAnimOptions& o, std::ofstream& frames_csv) {
    Scene& scene = s.loaded.scene;
    SceneAnimator& animator = *s.loaded.animator;
    // Every accelerator starts from frame 0 (the previous one left the scene at its last frame).
    animator.pose(scene, frame_time(0, o.fps));
    if (s.camera) scene.cameras[0] = *s.camera;
    AnimRow row;
    row.accel = accel;
    const RenderSettings rs = anim_settings(scene, accel, o.width, o.height, o.threads);
    Clock::time_point t0 = Clock::now();
    auto renderer = std::make_unique<Renderer>(scene, rs);
    row.build = seconds_since(t0);
    t0 = Clock::now();
    (void)renderer->render();
    row.render = seconds_since(t0);

    const std::set<int> rebuild_at = rebuild_set(s.frames, o.rebuild_frames);
    for (int k = 1; k < s.frames; ++k) {
        const double time = frame_time(k, o.fps);
        // The frame as `render --frames` updates it: pose, the fixed camera back, the renderer brought up to date.
        t0 = Clock::now();
        SceneUpdate u = animator.pose(scene, time);
        const double pose = seconds_since(t0);
        const Clock::time_point t1 = Clock::now();
        if (s.camera) {
            scene.cameras[0] = *s.camera;
            u.cameras = true;
        }
        bool refit = false;
        if (u.reloaded) renderer = std::make_unique<Renderer>(scene, rs);
        else refit = renderer->update(u).refit;
        const double update = seconds_since(t1);
        row.pose.push_back(pose);
        row.update.push_back(update);
        row.frame.push_back(pose + update);
        row.refit += refit ? 1 : 0;
        ++row.updated;
        frames_csv << fmt::format("{},{},{},{:.6f},{:.6f},{:.6f},{}\n", s.label, accel, k, time, pose, update,
                                  refit ? "refit" : u.reloaded ? "reloaded" : "rebuilt");
        if (!rebuild_at.count(k)) continue;
        // The same frame without the animator: loaded at its time and built anew.
        {
            t0 = Clock::now();
            const Scene fresh = load_scene(s.path, anim_import(time));
            const Renderer r(fresh, anim_settings(fresh, accel, o.width, o.height, o.threads));
            row.rebuild_full.push_back(seconds_since(t0));
        }
        // A new Renderer on the posed scene: the accelerator built from scratch; the updated one must agree with it.
        t0 = Clock::now();
        const Renderer r(scene, rs);
        row.rebuild_renderer.push_back(seconds_since(t0));
        row.rebuild_accel.push_back(r.accelerator().stats().build_seconds);
        row.check_mismatches += compare_hits(renderer->accelerator(), r.accelerator(), scene, o.check_rays, uint32_t(k));
        row.check_rays += size_t(o.check_rays);
    }
    frames_csv.flush();
    return row;
}

/// What the CesiumMan sequence measured.
struct SequenceRow {
    std::string accel;
    double load = 0.0, bounds = 0.0, build = 0.0, pose = 0.0, update = 0.0, render = 0.0, total = 0.0;
    size_t refit = 0;
    double ratio() const { return render > 0.0 ? total / render : 0.0; }
};

/// `render --frames 0-(n-1)` without writing images: one load, the camera's bounds, one build,
/// then pose + update + render per frame.
SequenceRow measure_sequence(const std::string& path, const std::string& accel, const BenchAnimOptions& o) {
    SequenceRow row;
    row.accel = accel;
    const int n = o.sequence_frames;
    const Clock::time_point start = Clock::now();
    AnimatedScene a = load_animated_scene(path, anim_import(frame_time(0, o.fps)));
    row.load = seconds_since(start);
    Clock::time_point t0 = Clock::now();
    const std::optional<Camera> camera = sequence_camera(a.scene, *a.animator, n, o.fps);
    row.bounds = seconds_since(t0);
    const RenderSettings rs = anim_settings(a.scene, accel, o.sequence_width, o.sequence_height, o.threads);
    t0 = Clock::now();
    auto renderer = std::make_unique<Renderer>(a.scene, rs);
    row.build = seconds_since(t0);
    for (int k = 0; k < n; ++k) {
        if (k > 0) {
            t0 = Clock::now();
            SceneUpdate u = a.animator->pose(a.scene, frame_time(k, o.fps));
            row.pose += seconds_since(t0);
            t0 = Clock::now();
            if (camera) {
                a.scene.cameras[0] = *camera;
                u.cameras = true;
            }
            if (u.reloaded) renderer = std::make_unique<Renderer>(a.scene, rs);
            else row.refit += renderer->update(u).refit ? 1 : 0;
            row.update += seconds_since(t0);
        }
        t0 = Clock::now();
        (void)renderer->render();
        row.render += seconds_since(t0);
    }
    row.total = seconds_since(start);
    return row;
}

const char* verdict(double value, double target) { return value <= target ? "PASS" : "MISS"; }

void check_options(const BenchAnimOptions& o) {
    if (o.accels.empty()) throw Error("bench anim: --accel: give at least one accelerator");
    if (o.scenes.empty()) throw Error("bench anim: --scenes: give cesium, generated or both");
    for (const std::string& s : o.scenes)
        if (s != "cesium" && s != "generated")
            throw Error(fmt::format("bench anim: --scenes: unknown scene '{}' (available: cesium, generated)", s));
    if (o.frames < 2 || o.cesium_frames < 2)
        throw Error(fmt::format("bench anim: --frames and --cesium-frames: at least 2 (got {} and {})", o.frames,
                                o.cesium_frames));
    if (!(o.fps > 0.0 && std::isfinite(o.fps))) throw Error(fmt::format("bench anim: --fps {}: expected a positive number", o.fps));
    if (o.triangles < 24) throw Error(fmt::format("bench anim: --triangles {}: at least 24", o.triangles));
}

int run_bench_anim(const BenchAnimOptions& o) {
    check_options(o);
    const fs::path out(o.out);
    fs::create_directories(out);
    std::ofstream csv(out / "anim.csv");
    csv << "scene,triangles,deforming_meshes,deforming_vertices,accel,frames,fps,width,height,threads,load_seconds,"
           "build_seconds,render_seconds,pose_median_seconds,pose_max_seconds,update_median_seconds,update_max_seconds,"
           "frame_update_median_seconds,frame_update_max_seconds,accel_update,refit_frames,updated_frames,rebuild_frames,"
           "rebuild_load_build_median_seconds,rebuild_renderer_median_seconds,rebuild_accel_median_seconds,"
           "update_render_ratio,ratio_target,verdict,check_rays,check_mismatches,load_average\n";
    std::ofstream frames_csv(out / "anim_frames.csv");
    frames_csv << "scene,accel,frame,time,pose_seconds,update_seconds,accel_update\n";

    std::vector<AnimScene> scenes;
    fs::path generated;
    for (const std::string& which : o.scenes) {
        AnimScene s;
        s.label = which == "cesium" ? "CesiumMan" : "generated";
        if (which == "cesium") {
            s.path = cesium_path();
            s.frames = o.cesium_frames;
        } else {
            generated = out / fmt::format("generated_skin_{}.glb", o.triangles);
            GeneratedSkinSpec spec;
            spec.triangles = o.triangles;
            spec.joints = o.joints;
            const GeneratedSkin g = write_generated_skin(generated, spec);
            std::printf("generated %s: %zu triangles, %zu vertices (%d x %d), %d joints, %.1f MB\n", generated.c_str(),
                        g.triangles, g.vertices, g.segments, g.rings, spec.joints, double(g.bytes) / 1e6);
            s.path = generated.string();
            s.frames = o.frames;
        }
        scenes.push_back(std::move(s));
    }

    std::printf("== bench anim: per-frame update (pose + Renderer::update) against a full rebuild and a %dx%d render; "
                "frames at k/%g s, animations looping; wall clock, %s threads (load %.2f)\n",
                o.width, o.height, o.fps, o.threads ? std::to_string(o.threads).c_str() : "all", load_average_1min());
    std::printf("   times in ms unless [s]; rebuild = load_scene + new Renderer; build = new Renderer alone (accelerator's own)\n");
    std::printf("   %-10s %9s %-7s %6s %14s %14s %14s %-8s %10s %16s %10s %8s %s\n", "scene", "triangles", "accel", "frames",
                "pose med/max", "update med/max", "frame med/max", "accel", "rebuild", "build (accel)", "render[s]",
                "upd/rnd", "target <= 10 %");
    for (AnimScene& s : scenes) {
        Clock::time_point t0 = Clock::now();
        s.loaded = load_animated_scene(s.path, anim_import(0.0));
        s.load_seconds = seconds_since(t0);
        s.camera = sequence_camera(s.loaded.scene, *s.loaded.animator, s.frames, o.fps);
        s.triangles = s.loaded.scene.instanced_triangle_count();
        for (const Mesh& m : s.loaded.scene.meshes)
            if (m.deforming) {
                ++s.deforming_meshes;
                s.deforming_vertices += m.positions.size();
            }
        for (const std::string& accel : o.accels) {
            const AnimRow r = measure(s, accel, o, frames_csv);
            const double ms = 1e3;
            std::printf("   %-10s %9zu %-7s %6d %6.1f/%7.1f %6.1f/%7.1f %6.1f/%7.1f %-8s %10.1f %7.1f (%6.1f) %10.3f %7.1f%% %s\n",
                        s.label.c_str(), s.triangles, accel.c_str(), s.frames, ms * median(r.pose), ms * max_of(r.pose),
                        ms * median(r.update), ms * max_of(r.update), ms * median(r.frame), ms * max_of(r.frame),
                        r.accel_update().c_str(), ms * median(r.rebuild_full), ms * median(r.rebuild_renderer),
                        ms * median(r.rebuild_accel), r.render, 100.0 * r.ratio(), verdict(r.ratio(), kUpdateTarget));
            if (r.check_mismatches)
                std::printf("   WARNING: %zu of %zu check rays hit differently with the updated and a new %s accelerator\n",
                            r.check_mismatches, r.check_rays, accel.c_str());
            csv << fmt::format("{},{},{},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{},{},{},{},"
                               "{:.6f},{:.6f},{:.6f},{:.6f},{:.2f},{},{},{},{:.2f}\n",
                               s.label, s.triangles, s.deforming_meshes, s.deforming_vertices, accel, s.frames, o.fps,
                               o.width, o.height, o.threads, s.load_seconds, r.build, r.render, median(r.pose), max_of(r.pose),
                               median(r.update), max_of(r.update), median(r.frame), max_of(r.frame), r.accel_update(),
                               r.refit, r.updated, r.rebuild_full.size(), median(r.rebuild_full), median(r.rebuild_renderer),
                               median(r.rebuild_accel), r.ratio(), kUpdateTarget, verdict(r.ratio(), kUpdateTarget),
                               r.check_rays, r.check_mismatches, load_average_1min());
            csv.flush();
            std::fflush(stdout);
        }
        std::printf("   %s: %zu deforming mesh(es), %zu vertices; loaded in %.3f s\n", s.label.c_str(), s.deforming_meshes,
                    s.deforming_vertices, s.load_seconds);
        s.loaded = AnimatedScene{};  // the next scene's memory
    }
    if (!generated.empty() && !o.keep) fs::remove(generated);
    std::printf("wrote %s, %s\n", (out / "anim.csv").c_str(), (out / "anim_frames.csv").c_str());

    if (o.sequence_frames > 0) {
        std::ofstream seq(out / "anim_sequence.csv");
        seq << "scene,accel,frames,fps,width,height,threads,load_seconds,bounds_seconds,build_seconds,pose_seconds,"
               "update_seconds,render_seconds,total_seconds,ratio,ratio_target,verdict,refit_frames,load_average\n";
        std::printf("\n== bench anim: a %d-frame CesiumMan sequence at %dx%d, start to last frame rendered (no image "
                    "written) against the sum of its render times (load %.2f)\n",
                    o.sequence_frames, o.sequence_width, o.sequence_height, load_average_1min());
        std::printf("   %-7s %8s %9s %9s %9s %9s %10s %9s %7s %s\n", "accel", "load[s]", "bounds[s]", "build[s]",
                    "pose[s]", "update[s]", "render[s]", "total[s]", "ratio", "target <= 1.2x");
        for (const std::string& accel : o.accels) {
            const SequenceRow r = measure_sequence(cesium_path(), accel, o);
            std::printf("   %-7s %8.3f %9.3f %9.3f %9.3f %9.3f %10.3f %9.3f %6.3fx %s\n", accel.c_str(), r.load, r.bounds,
                        r.build, r.pose, r.update, r.render, r.total, r.ratio(), verdict(r.ratio(), kSequenceTarget));
            seq << fmt::format("CesiumMan,{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.4f},{:.1f},{},{},{:.2f}\n",
                               accel, o.sequence_frames, o.fps, o.sequence_width, o.sequence_height, o.threads, r.load,
                               r.bounds, r.build, r.pose, r.update, r.render, r.total, r.ratio(), kSequenceTarget,
                               verdict(r.ratio(), kSequenceTarget), r.refit, load_average_1min());
            seq.flush();
            std::fflush(stdout);
        }
        std::printf("wrote %s\n", (out / "anim_sequence.csv").c_str());
    }
    return 0;
}

}  // namespace

Command register_bench_anim(CLI::App& bench) {
    auto o = std::make_shared<BenchAnimOptions>();
    auto quick = std::make_shared<bool>(false);
    CLI::App* app = bench.add_subcommand(
        "anim", "Per-frame update of an animated scene (pose + accelerator refit) against a full rebuild and the "
                "frame's render time, on CesiumMan and a generated skinned mesh (docs/performance.md)");
    app->add_option("--accel", o->accels, "Accelerators, comma-separated")->delimiter(',')->capture_default_str();
    app->add_option("--scenes", o->scenes, "Scenes, comma-separated: cesium, generated")->delimiter(',')->capture_default_str();
    app->add_option("--triangles", o->triangles, "Generated mesh: about this many triangles")->capture_default_str();
    app->add_option("--joints", o->joints, "Generated mesh: joints in the chain")->check(CLI::Range(4, 1000))->capture_default_str();
    app->add_option("--frames", o->frames, "Generated mesh: frames measured (frame 0 is the load)")->capture_default_str();
    app->add_option("--cesium-frames", o->cesium_frames, "CesiumMan: frames measured")->capture_default_str();
    app->add_option("--fps", o->fps, "Frames per second: frame k is at k / fps seconds")->capture_default_str();
    app->add_option("--width", o->width, "Render width of the update/render ratio")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--height", o->height, "Render height")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--rebuild-frames", o->rebuild_frames, "Frames (evenly spread) at which a full rebuild is timed")
        ->check(CLI::Range(1, 100000))->capture_default_str();
    app->add_option("--check-rays", o->check_rays, "Rays comparing the updated accelerator with a new one per rebuild frame")
        ->check(CLI::Range(0, 10000000))->capture_default_str();
    app->add_option("--sequence-frames", o->sequence_frames, "CesiumMan sequence length (0: no sequence)")
        ->check(CLI::Range(0, 100000))->capture_default_str();
    app->add_option("--sequence-width", o->sequence_width, "Sequence render width")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--sequence-height", o->sequence_height, "Sequence render height")->check(CLI::Range(1, 16384))->capture_default_str();
    app->add_option("--threads", o->threads, "Render threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--out", o->out, "Output directory: anim.csv, anim_frames.csv, anim_sequence.csv")->capture_default_str();
    app->add_flag("--keep", o->keep, "Keep the generated .glb in --out");
    app->add_flag("--quick", *quick, "A small run (20k triangles, 6 frames, 320x180, a 12-frame sequence at 160x90); "
                                     "flags given explicitly still apply");
    return Command{app, [o, quick, app] {
        if (*quick) {
            // Only what the command line did not set.
            if (!app->count("--triangles")) o->triangles = 20000;
            if (!app->count("--frames")) o->frames = 6;
            if (!app->count("--cesium-frames")) o->cesium_frames = 6;
            if (!app->count("--width")) o->width = 320;
            if (!app->count("--height")) o->height = 180;
            if (!app->count("--rebuild-frames")) o->rebuild_frames = 2;
            if (!app->count("--sequence-frames")) o->sequence_frames = 12;
            if (!app->count("--sequence-width")) o->sequence_width = 160;
            if (!app->count("--sequence-height")) o->sequence_height = 90;
        }
        return run_bench_anim(*o);
    }};
}

}  // namespace whitted::app
