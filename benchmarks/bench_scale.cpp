// `whitted bench scale`: how load, build and render time and memory grow with the number of
// objects (docs/performance.md, "whitted bench scale").
//
// Generates, for every size of --sizes, a scene file of that many analytic spheres (a cubic
// lattice, three materials, one light) and, for the sizes up to --max-nodes, a glTF file of that
// many nodes each with its own small mesh (a tetrahedron: own accessors and bufferViews). Each is
// measured in a child process of its own (fork), so one size's memory does not hide the next's:
// load_scene, the accelerator build (Renderer construction), a --width x --width render, and the
// child's peak resident memory above what it held before loading (VmHWM after resetting it
// through /proc/self/clear_refs; bytes per object). Prints a table, writes <out>/scale.csv and
// (python3 with matplotlib) the log-log plot through scripts/plot_scale.py.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/bench_images.h"
#include "benchmarks/bench_timing.h"
#include "importers/scene_loader.h"
#include "core/error.h"
#include "core/log.h"
#include "integrator/render.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;

struct BenchScaleOptions {
    std::vector<size_t> sizes{1000, 10000, 100000, 1000000};  ///< object counts
    size_t max_nodes = 100000;                                ///< largest glTF node count (memory)
    int width = 64;                                           ///< render size (square)
    int threads = 0;                                          ///< 0 = all cores
    std::string out = "bench-scale";
    bool plot = true;
    bool keep = false;  ///< keep the generated files
    std::string python = default_python();
};

void write_spheres(const fs::path& path, size_t n) {
    std::ofstream f(path, std::ios::binary);
    size_t side = 1;
    while (side * side * side < n) ++side;
    const double extent = 2.0 * double(side);
    f << "{\"version\": 1,\n \"camera\": {\"type\": \"perspective\", \"position\": [" << 1.6 * extent << ", "
      << 1.3 * extent << ", " << 1.9 * extent << "], \"look_at\": [" << side << ", " << side << ", " << side
      << "], \"up\": [0, 1, 0], \"fov\": 40},\n"
      << " \"materials\": {\"red\": {\"kd\": [0.8, 0.2, 0.2]}, \"grey\": {\"kd\": 0.5}, \"mirror\": {\"kd\": 0.3, \"kr\": 0.5}},\n"
      << " \"lights\": [{\"type\": \"point\", \"position\": [" << 3 * extent << ", " << 4 * extent << ", " << extent
      << "], \"color\": [1, 1, 1], \"intensity\": 1}],\n \"objects\": [\n";
    static const char* const kMaterials[] = {"red", "grey", "mirror"};
    std::string line;
    for (size_t i = 0; i < n; ++i) {
        line = fmt::format("{{\"type\": \"sphere\", \"center\": [{}, {}, {}], \"radius\": 0.8, \"material\": \"{}\"}}{}\n",
                           2 * (i % side), 2 * ((i / side) % side), 2 * (i / (side * side)), kMaterials[i % 3],
                           i + 1 < n ? "," : "");
        f << line;
    }
    f << "]}\n";
}

void write_nodes(const fs::path& path, size_t n) {
    // One buffer: a tetrahedron's 4 positions and 12 indices, referenced by every mesh's own views.
    const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint16_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    {
        std::ofstream bin(fs::path(path).replace_extension(".bin"), std::ios::binary);
        bin.write(reinterpret_cast<const char*>(positions), sizeof positions);
        bin.write(reinterpret_cast<const char*>(indices), sizeof indices);
    }
    std::ofstream f(path, std::ios::binary);
    auto list = [&](const char* key, auto&& item) {
        f << ",\n \"" << key << "\": [";
        for (size_t i = 0; i < n; ++i) f << (i ? ",\n  " : "\n  ") << item(i);
        f << "]";
    };
    f << "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0";
    f << ",\n \"scenes\": [{\"nodes\": [";
    for (size_t i = 0; i < n; ++i) f << (i ? "," : "") << i;
    f << "]}]";
    const size_t side = 100;
    list("nodes", [&](size_t i) {
        return fmt::format("{{\"mesh\": {}, \"translation\": [{}, {}, {}]}}", i, 2 * (i % side), 2 * ((i / side) % side),
                           2 * (i / (side * side)));
    });
    list("meshes", [](size_t i) {
        return fmt::format("{{\"primitives\": [{{\"attributes\": {{\"POSITION\": {}}}, \"indices\": {}}}]}}", 2 * i, 2 * i + 1);
    });
    list("accessors", [](size_t i) {
        return fmt::format("{{\"bufferView\": {}, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", "
                           "\"min\": [0, 0, 0], \"max\": [1, 1, 1]}},\n  "
                           "{{\"bufferView\": {}, \"componentType\": 5123, \"count\": 12, \"type\": \"SCALAR\"}}",
                           2 * i, 2 * i + 1);
    });
    list("bufferViews", [](size_t) {
        return std::string("{\"buffer\": 0, \"byteLength\": 48},\n  {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 24}");
    });
    f << ",\n \"buffers\": [{\"byteLength\": 72, \"uri\": \"" << fs::path(path).replace_extension(".bin").filename().string()
      << "\"}]}\n";
}

/// What a child measured.
struct Measure {
    double load = 0, build = 0, render = 0;
    double peak_bytes = 0;   ///< peak RSS above what the child held before loading
    double accel_bytes = 0;  ///< the accelerator's own count
    size_t primitives = 0;   ///< spheres + triangles (instanced)
    bool ok = false;
    char error[512] = {};
};

long status_kib(const char* key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    const size_t n = std::strlen(key);
    while (std::getline(f, line))
        if (line.compare(0, n, key) == 0) return std::atol(line.c_str() + n);
    return -1;
}

Measure measure_child(const fs::path& file, const BenchScaleOptions& o) {
    Measure m;
    try {
        std::ofstream("/proc/self/clear_refs") << "5";  // resets VmHWM to the current RSS
        const double before = double(status_kib("VmRSS:")) * 1024.0;
        ImportOptions io;
        io.no_environment = true;
        const auto t0 = std::chrono::steady_clock::now();
        const Scene scene = load_scene(file.string(), io);
        const auto t1 = std::chrono::steady_clock::now();
        RenderSettings rs;
        apply_scene_settings(scene.settings, rs);
        rs.width = rs.height = o.width;
        rs.threads = o.threads;
        rs.progress = false;
        const Renderer renderer(scene, rs);
        const auto t2 = std::chrono::steady_clock::now();
        (void)renderer.render();
        const auto t3 = std::chrono::steady_clock::now();
        m.load = std::chrono::duration<double>(t1 - t0).count();
        m.build = std::chrono::duration<double>(t2 - t1).count();
        m.render = std::chrono::duration<double>(t3 - t2).count();
        m.peak_bytes = double(status_kib("VmHWM:")) * 1024.0 - before;
        m.accel_bytes = double(renderer.accelerator().stats().bytes);
        m.primitives = scene.spheres.size() + scene.instanced_triangle_count();
        m.ok = true;
    } catch (const std::exception& e) {
        std::snprintf(m.error, sizeof m.error, "%s", e.what());
    }
    return m;
}

/// Runs measure_child in a forked process; its result comes back through a pipe.
Measure measure(const fs::path& file, const BenchScaleOptions& o) {
    int fds[2];
    if (pipe(fds) != 0) throw Error("bench scale: pipe failed");
    std::fflush(nullptr);
    const pid_t pid = fork();
    if (pid < 0) throw Error("bench scale: fork failed");
    if (pid == 0) {
        close(fds[0]);
        // The table is the output: the child's import and build notes stay quiet unless asked.
        if (log_level() < LogLevel::Warning) set_log_level(LogLevel::Warning);
        const Measure m = measure_child(file, o);
        const ssize_t w = write(fds[1], &m, sizeof m);
        _exit(w == ssize_t(sizeof m) ? 0 : 1);
    }
    close(fds[1]);
    Measure m;
    const ssize_t r = read(fds[0], &m, sizeof m);
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (r != ssize_t(sizeof m) || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw Error(fmt::format("bench scale: the measurement of {} died (signal or out of memory)", file.string()));
    if (!m.ok) throw Error(fmt::format("bench scale: {}: {}", file.string(), m.error));
    return m;
}

int run_bench_scale(const BenchScaleOptions& o) {
    if (o.sizes.empty()) throw Error("bench scale: --sizes: give at least one size");
    for (const size_t n : o.sizes)
        if (n == 0) throw Error("bench scale: --sizes: object counts are 1 or more (got 0)");
    const fs::path out(o.out);
    fs::create_directories(out);
    std::ofstream csv(out / "scale.csv");
    csv << "kind,objects,primitives,file_bytes,load_seconds,build_seconds,render_seconds,peak_bytes,"
           "peak_bytes_per_object,accel_bytes,accel_bytes_per_primitive,width,threads,load\n";
    std::printf("== bench scale: load, build and %dx%d render in a child process each; peak RSS above the child's "
                "start (load %.2f)\n", o.width, o.width, load_average_1min());
    std::printf("   %-7s %9s %12s %9s %9s %9s %12s %10s %12s\n", "kind", "objects", "file bytes", "load[s]", "build[s]",
                "render[s]", "peak[MB]", "B/object", "accel B/prim");
    for (const char* kind : {"spheres", "nodes"}) {
        for (const size_t n : o.sizes) {
            const bool spheres = std::string(kind) == "spheres";
            if (!spheres && n > o.max_nodes) continue;
            const fs::path file = out / fmt::format("{}_{}.{}", kind, n, spheres ? "json" : "gltf");
            if (spheres) write_spheres(file, n);
            else write_nodes(file, n);
            const Measure m = measure(file, o);
            const double bytes = double(fs::file_size(file));
            std::printf("   %-7s %9zu %12.0f %9.3f %9.3f %9.3f %12.1f %10.0f %12.1f\n", kind, n, bytes, m.load, m.build,
                        m.render, m.peak_bytes / 1e6, m.peak_bytes / double(n),
                        m.primitives ? m.accel_bytes / double(m.primitives) : 0.0);
            csv << fmt::format("{},{},{},{:.0f},{:.6f},{:.6f},{:.6f},{:.0f},{:.1f},{:.0f},{:.1f},{},{},{:.2f}\n", kind, n,
                               m.primitives, bytes, m.load, m.build, m.render, m.peak_bytes, m.peak_bytes / double(n),
                               m.accel_bytes, m.primitives ? m.accel_bytes / double(m.primitives) : 0.0, o.width,
                               o.threads, load_average_1min());
            csv.flush();
            std::fflush(stdout);
            if (!o.keep) {
                fs::remove(file);
                if (!spheres) fs::remove(fs::path(file).replace_extension(".bin"));
            }
        }
    }
    std::printf("wrote %s\n", (out / "scale.csv").c_str());
    if (o.plot) run_plot_script(o.python, "plot_scale.py", out / "scale.csv", out, "bench scale");
    return 0;
}

}  // namespace

Command register_bench_scale(CLI::App& bench) {
    auto o = std::make_shared<BenchScaleOptions>();
    CLI::App* app = bench.add_subcommand(
        "scale", "Load, build and render time and peak memory per object for generated scenes of 10^3 ... 10^6 "
                 "spheres and glTF nodes (docs/performance.md)");
    app->add_option("--sizes", o->sizes, "Object counts, comma-separated")->delimiter(',')->capture_default_str();
    app->add_option("--max-nodes", o->max_nodes, "Largest glTF node count (each node's own mesh costs memory)")
        ->capture_default_str();
    app->add_option("--width", o->width, "Render size in pixels (square)")->check(CLI::Range(1, 4096))->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--out", o->out, "Output directory: scale.csv, plot (the generated files are removed)")
        ->capture_default_str();
    app->add_flag("--keep", o->keep, "Keep the generated scene files in --out");
    app->add_flag("!--no-plot", o->plot, "Do not run scripts/plot_scale.py");
    app->add_option("--python", o->python, "Python interpreter with matplotlib for the plot")->capture_default_str();
    return Command{app, [o] { return run_bench_scale(*o); }};
}

}  // namespace whitted::app
