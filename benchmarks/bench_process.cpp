// `whitted bench process`: complete runs, process start to file written (docs/performance.md,
// "Whole-process benchmark").
//
// Each measurement spawns the `whitted` beside this program (or --exe) as a user would run it, `whitted
// render SCENE --width W --height H -o OUT`, and times it from spawn to exit (wall clock), with
// its peak resident memory (wait4's rusage). The run's own summary line gives the split: load,
// build, render and write; what is left of the wall time is start-up and exit (dynamic loading,
// initialisers, argument parsing, tearing down). `whitted --help` and `whitted info` of the
// first scene are timed the same way. Medians of --repeat runs; prints a table and writes
// <out>/process.csv.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "benchmarks/bench_commands.h"
#include "benchmarks/process_run.h"
#include "benchmarks/versus_povray.h"
#include "core/error.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;

struct BenchProcessOptions {
    std::vector<std::string> scenes;  ///< empty: the bundled scenes (see default_scenes)
    std::string sizes = "512x512,1920x1080";  ///< comma-separated WxH
    std::string formats = "png,exr";          ///< comma-separated
    int repeat = 3;
    int threads = 0;
    std::string out = "out/bench_process";
    std::string exe;  ///< the whitted to run; empty = this executable
    bool vs_povray = false;           ///< run the comparison with POV-Ray instead (versus_povray.h)
    VersusPovrayOptions povray;
};

std::vector<std::string> default_scenes() {
    const std::string a = std::string(WHITTED_SOURCE_DIR) + "/assets/";
    return {a + "scenes/whitted1980.json", a + "scenes/glass_mirror_room.json", a + "scenes/transparent_shadows.json",
            a + "scenes/default.glb", a + "gltf/Box/glTF-Binary/Box.glb"};
}

/// The `whitted` program in the folder of this one (whitted-bench, which `whitted bench` runs).
std::string whitted_beside_this_program() {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("bench process: cannot find this program (/proc/self/exe); give --exe");
    return (self.parent_path() / "whitted").string();
}

/// The options with the lists split.
struct BenchProcess {
    const BenchProcessOptions& options;
    std::vector<std::string> sizes, formats;
    const std::vector<std::string>& scenes = options.scenes;
    const int& repeat = options.repeat;
    const int& threads = options.threads;
    const std::string& out = options.out;
    std::string exe = options.exe.empty() ? whitted_beside_this_program() : options.exe;
};

Run run_whitted(const std::string& exe, const std::vector<std::string>& args, const fs::path& err_file) {
    return run_program(exe, "whitted", args, err_file);
}

/// The phases of a render's summary line ("time   load 0.073s  build 0.000s  render 0.094s  write 0.003s").
struct Phases {
    double load = 0, build = 0, render = 0, write = 0;
    bool found = false;
};

Phases parse_phases(const std::string& err) {
    Phases p;
    const size_t at = err.find("time   load ");
    if (at == std::string::npos) return p;
    p.found = std::sscanf(err.c_str() + at, "time   load %lfs build %lfs render %lfs write %lfs", &p.load, &p.build,
                          &p.render, &p.write) == 4;
    return p;
}


struct Row {
    std::string what, scene, size, format;
    double wall = 0, wall_min = 0, load = 0, build = 0, render = 0, write = 0, startup = 0;
    size_t peak = 0;
};

/// --repeat runs of `args`; medians of every column (the split of a render from its summary line).
Row measure(const std::vector<std::string>& args, const BenchProcess& o, const fs::path& err_file, bool render) {
    std::vector<double> wall, load, build, rend, write, startup, peak;
    for (int i = 0; i < o.repeat; ++i) {
        const Run r = run_whitted(o.exe, args, err_file);
        if (r.code != 0) {
            throw Error(fmt::format("bench process: `whitted {}` failed ({}): {}", fmt::join(args, " "), r.code,
                                    first_line(r.err)));
        }
        wall.push_back(r.seconds);
        peak.push_back(double(r.peak_bytes));
        if (render) {
            const Phases p = parse_phases(r.err);
            if (!p.found) throw Error(fmt::format("bench process: no summary line from `whitted {}`", fmt::join(args, " ")));
            load.push_back(p.load);
            build.push_back(p.build);
            rend.push_back(p.render);
            write.push_back(p.write);
            startup.push_back(std::max(0.0, r.seconds - (p.load + p.build + p.render + p.write)));
        }
    }
    Row row;
    row.wall = median(wall);
    row.wall_min = *std::min_element(wall.begin(), wall.end());
    row.load = median(load);
    row.build = median(build);
    row.render = median(rend);
    row.write = median(write);
    row.startup = render ? median(startup) : row.wall;
    row.peak = size_t(median(peak));
    return row;
}

bool parse_size(const std::string& s, int& w, int& h) {
    char x = 0;
    return std::sscanf(s.c_str(), "%d%c%d", &w, &x, &h) == 3 && (x == 'x' || x == 'X') && w > 0 && h > 0 && w <= 16384 &&
           h <= 16384;
}

std::vector<std::string> split_commas(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

int run_bench_process(const BenchProcessOptions& options) {
    if (options.vs_povray) {
        VersusPovrayOptions v = options.povray;
        v.whitted = options.exe.empty() ? whitted_beside_this_program() : options.exe;
        v.repeat = options.repeat;
        v.threads = options.threads;
        v.out = options.out;
        return run_versus_povray(v);
    }
    BenchProcess o{options, split_commas(options.sizes), split_commas(options.formats)};
    if (o.sizes.empty() || o.formats.empty()) throw Error("bench process: --sizes and --formats need at least one entry");
    const std::vector<std::string> scenes = o.scenes.empty() ? default_scenes() : o.scenes;
    for (const std::string& s : scenes)
        if (!fs::is_regular_file(s)) throw Error(fmt::format("bench process: {}: no such file", s));
    for (const std::string& s : o.sizes) {
        int w = 0, h = 0;
        if (!parse_size(s, w, h)) throw Error(fmt::format("bench process: --sizes: '{}' is not WxH", s));
    }
    for (const std::string& f : o.formats)
        if (f != "png" && f != "exr" && f != "jpg" && f != "tif")
            throw Error(fmt::format("bench process: --formats: '{}' (use png, exr, jpg, tif)", f));
    const fs::path out(o.out);
    fs::create_directories(out);
    const fs::path err_file = out / "stderr.txt";
    std::vector<std::string> common{"--no-progress"};
    if (o.threads > 0) common.insert(common.end(), {"--threads", std::to_string(o.threads)});

    std::printf("== bench process: whole runs of `whitted` (spawn to exit), median of %d; start-up+exit = wall - "
                "(load + build + render + write)\n",
                o.repeat);
    std::printf("%-44s %-10s %-4s %8s %8s %8s %8s %8s %8s %8s %8s\n", "run", "size", "fmt", "wall_s", "min_s", "start_s",
                "load_s", "build_s", "render_s", "write_s", "peak_MB");
    std::vector<Row> rows;
    auto print = [&](const Row& r) {
        std::printf("%-44s %-10s %-4s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f\n", r.what.c_str(), r.size.c_str(),
                    r.format.c_str(), r.wall, r.wall_min, r.startup, r.load, r.build, r.render, r.write,
                    double(r.peak) / (1 << 20));
        std::fflush(stdout);
        rows.push_back(r);
    };
    {
        Row r = measure({"--help"}, o, err_file, false);
        r.what = "--help";
        print(r);
        std::vector<std::string> info{"info", scenes.front()};
        r = measure(info, o, err_file, false);
        r.what = "info " + fs::path(scenes.front()).filename().string();
        r.scene = scenes.front();
        print(r);
    }
    for (const std::string& scene : scenes) {
        const bool box = fs::path(scene).filename() == "Box.glb";
        // Box is the small-render case of the fixed cost: 64x64 only.
        const std::vector<std::string> sizes = box ? std::vector<std::string>{"64x64"} : o.sizes;
        for (const std::string& size : sizes) {
            int w = 0, h = 0;
            parse_size(size, w, h);
            for (const std::string& format : o.formats) {
                const fs::path image = out / fmt::format("{}_{}.{}", fs::path(scene).stem().string(), size, format);
                std::vector<std::string> args{"render", scene, "--width", std::to_string(w), "--height", std::to_string(h),
                                              "-o", image.string()};
                args.insert(args.end(), common.begin(), common.end());
                Row r = measure(args, o, err_file, true);
                r.what = "render " + fs::path(scene).filename().string();
                r.scene = scene;
                r.size = size;
                r.format = format;
                print(r);
                fs::remove(image);
            }
        }
    }
    fs::remove(err_file);
    std::ofstream csv(out / "process.csv");
    csv << "run,scene,size,format,wall_seconds,wall_min_seconds,startup_exit_seconds,load_seconds,build_seconds,"
           "render_seconds,write_seconds,peak_bytes,repeat\n";
    for (const Row& r : rows)
        csv << fmt::format("{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{}\n", r.what, r.scene, r.size,
                           r.format, r.wall, r.wall_min, r.startup, r.load, r.build, r.render, r.write, r.peak, o.repeat);
    std::printf("wrote %s\n", (out / "process.csv").string().c_str());
    return 0;
}

}  // namespace

Command register_bench_process(CLI::App& bench) {
    auto o = std::make_shared<BenchProcessOptions>();
    CLI::App* app = bench.add_subcommand(
        "process", "Whole runs, process start to file written: the bundled scenes at 512x512 and 1920x1080 (Box at "
                   "64x64), --help and info, with the split start-up / load / build / render / write (docs/performance.md)");
    app->add_option("scenes", o->scenes, "Scene files (default: the bundled scenes and Box)");
    app->add_option("--sizes", o->sizes, "Image sizes WxH, comma-separated")->capture_default_str();
    app->add_option("--formats", o->formats, "Output formats, comma-separated: png, exr, jpg, tif")->capture_default_str();
    app->add_option("--repeat", o->repeat, "Runs per measurement (the median is reported)")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads of the runs (0 = all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    app->add_option("--out", o->out, "Output directory: process.csv")->capture_default_str();
    app->add_option("--exe", o->exe, "The whitted executable to time (default: the one beside this program; another build for a before/after)")
        ->check(CLI::ExistingFile);
    app->add_flag("--vs-povray", o->vs_povray,
                  "Instead: whitted against POV-Ray 3.7 at equal error, whole runs, on the classic scene at 1920x1080 and "
                  "SPD-style scenes at 512x512 (docs/performance.md, \"Against POV-Ray\")");
    app->add_option("--povray", o->povray.povray, "--vs-povray: the POV-Ray program (a path, or a name on the PATH)")
        ->capture_default_str();
    app->add_option("--pov-scenes", o->povray.scenes,
                    "--vs-povray: scenes: whitted1980, the SPD-style rings, tree, balls, tetra, mount, gears, or classic "
                    "scene files (spheres, cylinders, cones, discs, meshes, planes, classic materials, point and "
                    "directional lights)")
        ->delimiter(',')
        ->check(CLI::IsMember(povray_scene_names()) | CLI::ExistingFile)
        ->capture_default_str();
    app->add_option("--spd-size", o->povray.spd_size, "--vs-povray: SPD size factor of the SPD-style scenes")
        ->check(CLI::Range(1, 6))
        ->capture_default_str();
    app->add_option("--pov-scale", o->povray.scale, "--vs-povray: image sizes times this (1: 1920x1080 and 512x512)")
        ->check(CLI::Range(0.01, 4.0))
        ->capture_default_str();
    return Command{app, [o] { return run_bench_process(*o); }};
}

}  // namespace whitted::app
