// The `whitted` program end to end: exit codes, one-line errors, outputs written.
#include <gtest/gtest.h>

#include "tests/support/cli_image.h"
#include "tests/support/cli_util.h"

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <csignal>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::slurp;
using whitted::test::wait_exit;



size_t line_count(const std::string& s) {
    size_t n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";

TEST(Cli, UnknownFlagIsOneLineAndExitTwo) {
    Result r = run("render '" + kBox + "' --no-such-flag");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
}

TEST(Cli, BadFlagValueIsOneLineAndExitTwo) {
    Result r = run("render '" + kBox + "' --max-depth -3");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    r = run("render '" + kBox + "' --log-level loud");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
}

// --env-occlusion takes off or a number of directions; anything else is one line naming the flag.
TEST(Cli, EnvOcclusionTakesOffOrACount) {
    for (const char* bad : {"5x", "2000", "-1", ""}) {
        const Result r = run("render '" + kBox + "' -o /dev/null --env-occlusion '" + bad + "'");
        EXPECT_NE(r.code, 0) << bad;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("--env-occlusion"), std::string::npos) << r.err;
    }
}

// `bench stability --accels` names backends of the self-intersection sweep: an unknown one is a
// one-line error, not an empty table.
TEST(Cli, BenchStabilityUnknownBackendIsOneLineAndExitTwo) {
    Result r = run("bench stability --sections self --accels bvh,no-such-backend");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("no-such-backend"), std::string::npos) << r.err;
}

TEST(Cli, MissingSubcommandOrFileIsExitTwo) {
    EXPECT_EQ(run("").code, 2);
    EXPECT_EQ(run("render").code, 2);
}

TEST(Cli, MissingSceneFileIsOneLineNamingIt) {
    Result r = run("render /nonexistent/scene.gltf -o /tmp/x.png");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("/nonexistent/scene.gltf"), std::string::npos) << r.err;
}

// --variant on render and info: a file without KHR_materials_variants is one error line naming
// it (the mapping itself: GltfVariants.* in test_gltf_variants), and nothing is written.
TEST(Cli, VariantOfAFileWithoutVariantsIsOneLine) {
    const std::string out = (std::filesystem::temp_directory_path() / "whitted_cli_variant.png").string();
    std::filesystem::remove(out);
    for (const std::string& cmd : {"render '" + kBox + "' --variant beach -o '" + out + "'",
                                   "info '" + kBox + "' --variant beach"}) {
        const Result r = run(cmd);
        EXPECT_EQ(r.code, 1) << cmd;
        EXPECT_NE(r.err.find("Box.glb"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("variant 'beach': the file has no KHR_materials_variants variants"), std::string::npos)
            << r.err;
    }
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(Cli, BrokenGltfIsOneLineNamingTheFile) {
    const std::string bad = std::string(WHITTED_TEST_DATA_DIR) + "/gltf-invalid/validator/node/node_loop.gltf";
    Result r = run("info '" + bad + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("node_loop.gltf"), std::string::npos) << r.err;
}

TEST(Cli, BadCameraIndexAndCropAreErrors) {
    Result r = run("render '" + kBox + "' --camera 7 -o /tmp/whitted_cli_cam.png --no-progress");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--camera 7"), std::string::npos) << r.err;
    r = run("render '" + kBox + "' --crop 1,2,3 -o /tmp/whitted_cli_crop.png --no-progress");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--crop"), std::string::npos) << r.err;
}

// --precision and --bv are the accelerator spec's options as flags: the same image as the spec
// form, and an error naming the spec where the backend has no such option.
TEST(Cli, PrecisionAndBvFlagsAreSpecOptions) {
    const fs::path a = fs::temp_directory_path() / "whitted_cli_prec_flag.exr";
    const fs::path b = fs::temp_directory_path() / "whitted_cli_prec_spec.exr";
    Result r = run("render '" + kBox + "' --width 24 --aa center --no-progress --exr-float --accel bvh --precision double "
                   "--bv sphere -o '" + a.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render '" + kBox + "' --width 24 --aa center --no-progress --exr-float "
            "--accel bvh:precision=double,bv=sphere -o '" + b.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<float> pa = whitted::test::read_pixels(a), pb = whitted::test::read_pixels(b);
    ASSERT_FALSE(pa.empty());
    EXPECT_EQ(pa, pb);
    r = run("render '" + kBox + "' --width 24 --no-progress --accel embree --precision double --log-level error "
            "-o /tmp/whitted_cli_p.png");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("embree:precision=double"), std::string::npos) << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    r = run("render '" + kBox + "' --width 24 --no-progress --bv cube -o /tmp/whitted_cli_p.png");
    EXPECT_EQ(r.code, 2) << r.err;
}

// Embree's robust (watertight-at-edges) mode is the default; --no-robust turns it off. The log
// says which one ran.
TEST(Cli, EmbreeRobustIsTheDefaultAndNoRobustTurnsItOff) {
    Result r = run("render '" + kBox + "' --width 16 --no-progress -o /tmp/whitted_cli_robust.png");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("accelerator: embree (robust)"), std::string::npos) << r.err;
    r = run("render '" + kBox + "' --width 16 --no-progress --no-robust -o /tmp/whitted_cli_robust.png");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("accelerator: embree (not robust"), std::string::npos) << r.err;
}

/// A compression flag (`--exr-compression`, `--tiff-compression`): `none` and the default write
/// the same pixels, `none` the larger file; a name the flag does not take is exit 2, one line.
void expect_compression_flag(const std::string& flag, const std::string& ext, const std::string& extra,
                             const std::string& bad, const std::string& message) {
    const fs::path none = fs::temp_directory_path() / ("whitted_cli_none" + ext);
    const fs::path zip = fs::temp_directory_path() / ("whitted_cli_zip" + ext);
    const std::string common = "render '" + kBox + "' --width 32 --aa center --no-progress " + extra;
    Result r = run(common + " " + flag + " none -o '" + none.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    r = run(common + " -o '" + zip.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(whitted::test::read_pixels(none), whitted::test::read_pixels(zip));  // lossless both ways
    EXPECT_GT(fs::file_size(none), fs::file_size(zip));
    r = run(common + " " + flag + " " + bad + " -o /tmp/whitted_cli_bad" + ext);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
}

TEST(Cli, ExrCompressionFlagWritesTheMethodAndRejectsOthers) {
    expect_compression_flag("--exr-compression", ".exr", "--exr-float", "dwaa", "unknown EXR compression 'dwaa'");
}

TEST(Cli, TiffCompressionFlagWritesTheMethodAndRejectsOthers) {
    expect_compression_flag("--tiff-compression", ".tif", "", "lzw", "unknown TIFF compression 'lzw'");
}

TEST(Cli, UnknownOutputExtensionIsAnErrorAndWritesNothing) {
    const fs::path out = fs::temp_directory_path() / "whitted_cli_out.xyz";
    fs::remove(out);
    Result r = run("render '" + kBox + "' --width 16 --no-progress -o '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("whitted_cli_out.xyz"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, RenderWritesPngAndExrWithAovsAndPrintsStats) {
    const fs::path png = fs::temp_directory_path() / "whitted_cli_box.png";
    const fs::path exr = fs::temp_directory_path() / "whitted_cli_box.exr";
    fs::remove(png);
    fs::remove(exr);
    Result r = run("render '" + kBox + "' --width 48 --no-progress -o '" + png.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(png));
    EXPECT_NE(r.err.find("Mrays/s"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("shadow"), std::string::npos) << r.err;
    r = run("render '" + kBox + "' --width 48 --height 20 --no-progress --aov depth,normal -o '" + exr.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(exr));
}

TEST(Cli, HelpDocumentsFlagsWithDefaults) {
    Result r = run("render --help");
    EXPECT_EQ(r.code, 0);
    for (const char* flag : {"--max-depth", "--background", "--ambient", "--exposure", "--camera", "--aov", "--crop",
                             "--threads", "--view", "--fresnel", "--refract-thin", "--width", "--height"})
        EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
    EXPECT_NE(r.out.find("=5"), std::string::npos) << "max-depth default shown";
}

/// The camera rays of a render's summary ("rays   camera N ...").
long long camera_rays(const std::string& err) {
    const std::string key = "rays   camera ";
    const size_t at = err.find(key);
    return at == std::string::npos ? -1 : std::stoll(err.substr(at + key.size()));
}

// One frame path: samples that tiles share are traced once in a process, so the 4 corners of
// --aa corners cost exactly (W+1)(H+1) camera rays whatever the tiles and threads, and adaptive
// anti-aliasing traces the same rays too.
TEST(Cli, SharedSamplesAreTracedOnceForAnyTileSizeAndThreads) {
    const std::string scene = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";
    const fs::path out = fs::temp_directory_path() / ("whitted_cli_corners_" + std::to_string(::getpid()) + ".exr");
    for (const char* aa : {"corners", "adaptive"}) {
        long long first = -1;
        for (const char* tiling : {"--tile-size 7 --threads 1", "--tile-size 32 --threads 2", "--tile-size 64 --threads 3",
                                   "--tile-size 13 --threads 3"}) {
            const Result r = run("render '" + scene + "' --width 60 --height 45 --no-progress --aa " + aa + " " + tiling +
                                 " -o '" + out.string() + "'");
            ASSERT_EQ(r.code, 0) << r.err;
            const long long rays = camera_rays(r.err);
            if (std::string(aa) == "corners") {
                EXPECT_EQ(rays, 61 * 46) << tiling;
            }
            if (first < 0) first = rays;
            EXPECT_EQ(rays, first) << aa << " " << tiling;
        }
    }
    fs::remove(out);
}

// `whitted bench ...` runs the whitted-bench program beside whitted, with the same arguments (global
// options before `bench` included); where it is not built, one line says so.
TEST(Cli, BenchRunsTheBenchProgramBesideIt) {
    Result r = run("--log-level error bench --help");
    EXPECT_EQ(r.code, 0) << r.err;
    for (const char* name : {"accel", "aa", "env", "process", "scale", "skip", "stability"})
        EXPECT_NE(r.out.find(name), std::string::npos) << name << "\n" << r.out;
    r = run("--help");
    EXPECT_NE(r.out.find("bench"), std::string::npos) << r.out;
    const fs::path dir = whitted::test::scratch_dir("whitted_cli", "alone");
    const fs::path alone = dir / "whitted";
    fs::copy_file(WHITTED_EXE, alone, fs::copy_options::overwrite_existing);
    r = whitted::test::run_program(alone.string(), "bench accel --help");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("whitted-bench"), std::string::npos) << r.err;
    r = whitted::test::run_program(alone.string(), "info '" + kBox + "'");  // the rest works without it
    EXPECT_EQ(r.code, 0) << r.err;
}

// `render --help` shows the flags in groups by task, measurement knobs under Diagnostics.
TEST(Cli, HelpGroupsFlagsByTask) {
    const Result r = run("render --help");
    ASSERT_EQ(r.code, 0);
    size_t last = 0;
    for (const char* group : {"Output", "Sampling", "Lighting", "Acceleration", "Distributed", "Diagnostics"}) {
        const size_t at = r.out.find(std::string("[Option Group: ") + group + "]");
        ASSERT_NE(at, std::string::npos) << group << "\n" << r.out;
        EXPECT_GT(at, last) << group;  // in this order
        last = at;
    }
    const size_t diagnostics = r.out.find("[Option Group: Diagnostics]");
    for (const char* knob : {"--no-specialize", "--tile-order", "--tile-log"})
        EXPECT_GT(r.out.find(knob), diagnostics) << knob;
    EXPECT_LT(r.out.find("--aa-threshold"), r.out.find("[Option Group: Lighting]"));
}

// `info` of a scene under an environment with hundreds of lights fits a screen; --verbose lists all.
TEST(Cli, InfoSummarisesEnvironmentLights) {
    Result r = run("info '" + kBox + "' --environment studio --env-lights 256");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_LE(line_count(r.out), 60u) << r.out;
    EXPECT_NE(r.out.find("lights_share="), std::string::npos) << r.out;
    const Result v = run("info '" + kBox + "' --environment studio --env-lights 256 --verbose");
    ASSERT_EQ(v.code, 0) << v.err;
    EXPECT_NE(v.out.find("light[255]: "), std::string::npos) << v.out;
    EXPECT_GT(line_count(v.out), 256u);
}

// Animated glTF (docs/gltf-support.md "Animation"): --time and --animation choose the moment;
// bad values are one line each, naming the flag or listing the animations the file has.
TEST(Cli, AnimationTimeAndChoice) {
    const std::string tri = std::string(WHITTED_ASSETS_DIR) + "/gltf/AnimatedTriangle/glTF/AnimatedTriangle.gltf";
    Result r = run("info '" + tri + "' --time 0.5");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("pose: time=0.5s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("animation[0]: name=\"animation 0\" duration=1s channels=1 interpolation=LINEAR posed=yes"),
              std::string::npos) << r.out;
    for (const char* bad : {"nan", "inf", "-1"}) {
        r = run("render '" + tri + "' --time " + bad + " -o /dev/null.png");
        EXPECT_NE(r.code, 0) << bad;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("--time"), std::string::npos) << r.err;
    }
    r = run("render '" + tri + "' --animation walk --no-progress -o /dev/null.png");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("no animation 'walk'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("0 \"animation 0\""), std::string::npos) << r.err;  // the ones that exist
}

// --frames A-B renders frame k at exactly --time k/fps into the '#' run of the output name: each
// frame bit for bit the separate render (here the scene file's own camera, so nothing else moves).
// A static file with --orbit turns the default camera, the first frame being the plain render.
TEST(Cli, FramesAreTheSeparateRenders) {
    const fs::path dir = whitted::test::scratch_dir("whitted_cli", "frames");
    const std::string tri = std::string(WHITTED_ASSETS_DIR) + "/gltf/AnimatedTriangle/glTF/AnimatedTriangle.gltf";
    const fs::path scene = dir / "tri.json";
    std::ofstream(scene) << R"({"version": 1, "camera": {"position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0]},
        "include": [{"file": ")" + tri + R"("}]})";
    const std::string common = " --width 24 --height 24 --no-progress --exr-float";
    Result r = run("render '" + scene.string() + "'" + common + " --frames 1-3 --fps 8 -o '" + (dir / "f_##.exr").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    for (int k = 1; k <= 3; ++k) {
        const fs::path frame = dir / ("f_0" + std::to_string(k) + ".exr");
        ASSERT_TRUE(fs::exists(frame)) << frame;
        char time[32];
        std::snprintf(time, sizeof time, "%.17g", double(k) / 8.0);
        r = run("render '" + scene.string() + "'" + common + " --time " + time + " -o '" + (dir / "one.exr").string() + "'");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(whitted::test::read_pixels(frame), whitted::test::read_pixels(dir / "one.exr")) << "frame " << k;
    }
    EXPECT_NE(whitted::test::read_pixels(dir / "f_01.exr"), whitted::test::read_pixels(dir / "f_03.exr"));
    // A glTF file is loaded once and posed in place per frame (the skinned mesh refit): SimpleSkin
    // with a camera node added, the same again.
    const fs::path skin_dir = fs::path(WHITTED_ASSETS_DIR) / "gltf/SimpleSkin/glTF";
    for (const auto& e : fs::directory_iterator(skin_dir))
        fs::copy_file(e.path(), dir / e.path().filename(), fs::copy_options::overwrite_existing);
    nlohmann::json gltf = nlohmann::json::parse(std::ifstream(skin_dir / "SimpleSkin.gltf"));
    gltf["cameras"] = nlohmann::json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.01}}}}});
    gltf["nodes"].push_back({{"camera", 0}, {"translation", {0.5, 1.0, 4.0}}});
    gltf["scenes"][0]["nodes"].push_back(gltf["nodes"].size() - 1);
    const fs::path skin = dir / "skin_camera.gltf";
    std::ofstream(skin) << gltf.dump();
    for (const char* accel : {"embree", "bvh"}) {
        r = run("render '" + skin.string() + "'" + common + " --accel " + accel + " --frames 0-3 --fps 2 -o '" +
                (dir / "s#.exr").string() + "'");
        ASSERT_EQ(r.code, 0) << r.err;
        for (int k = 0; k <= 3; ++k) {
            r = run("render '" + skin.string() + "'" + common + " --accel " + accel + " --time " +
                    std::to_string(k * 0.5) + " -o '" + (dir / "one.exr").string() + "'");
            ASSERT_EQ(r.code, 0) << r.err;
            EXPECT_EQ(whitted::test::read_pixels(dir / ("s" + std::to_string(k) + ".exr")),
                      whitted::test::read_pixels(dir / "one.exr"))
                << accel << " frame " << k;
        }
        EXPECT_NE(whitted::test::read_pixels(dir / "s0.exr"), whitted::test::read_pixels(dir / "s3.exr"));
    }
    // A turntable of a static file: frame 0 is the plain render, the next ones turn.
    r = run("render '" + kBox + "'" + common + " --frames 0-1 --orbit 90 -o '" + (dir / "t#.exr").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(run("render '" + kBox + "'" + common + " -o '" + (dir / "plain.exr").string() + "'").code, 0);
    EXPECT_EQ(whitted::test::read_pixels(dir / "t0.exr"), whitted::test::read_pixels(dir / "plain.exr"));
    EXPECT_NE(whitted::test::read_pixels(dir / "t1.exr"), whitted::test::read_pixels(dir / "plain.exr"));
    // No '#' in the name, or a bad range: one line, nothing written.
    r = run("render '" + kBox + "'" + common + " --frames 0-1 -o '" + (dir / "nohash.exr").string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("'#'"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "nohash.exr"));
    r = run("render '" + kBox + "'" + common + " --frames 3-1 -o '" + (dir / "bad#.exr").string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
}

TEST(Cli, InfoPrintsCounts) {
    Result r = run("info '" + kBox + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("12"), std::string::npos) << r.out;  // 12 triangles
}

// ---- scene files (docs/scene-format.md) ----

/// Writes a small scene file into a fresh folder and returns its path.
fs::path write_scene_file(const std::string& name, const std::string& text) {
    const fs::path p = whitted::test::process_folder("whitted_cli_scene") / name;
    std::ofstream(p) << text;
    return p;
}

const char* kSmallScene = R"({
  "version": 1,
  "render": {"width": 24, "height": 16, "aa": "center", "max_depth": 2, "output": "from_file.png"},
  "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov": 40},
  "materials": {"red": {"kd": [0.8, 0.1, 0.1]}, "glass": {"kt": 0.9, "ks": 0.05, "ior": 1.5}},
  "objects": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "red"},
    {"type": "sphere", "center": [0, 0.6, 0], "radius": 0.5, "material": "glass"}
  ],
  "lights": [{"type": "point", "position": [2, 4, 3], "intensity": 20}]
})";

TEST(Cli, SceneFileSettingsApplyAndFlagsOverrideThem) {
    const fs::path scene = write_scene_file("small.json", kSmallScene);
    const fs::path from_file = scene.parent_path() / "from_file.png";
    fs::remove(from_file);
    // No flags: size and output come from the file; the output is relative to the scene file.
    Result r = run("render '" + scene.string() + "' --no-progress");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(from_file));
    EXPECT_NE(r.err.find("(24x16)"), std::string::npos) << r.err;
    // Flags win over the file, each on its own: the depth from the flag, the size still the file's.
    const fs::path out = fs::temp_directory_path() / "whitted_cli_override.png";
    fs::remove(out);
    r = run("render '" + scene.string() + "' --no-progress --max-depth 0 -o '" + out.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(out));
    EXPECT_NE(r.err.find("(24x16)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("reflection 0  refraction 0"), std::string::npos) << r.err;
}

/// The size `whitted render` reports for `scene` rendered with `flags` ("" when it failed).
std::string rendered_size(const fs::path& scene, const std::string& flags) {
    const fs::path out = scene.parent_path() / "size.png";
    const Result r = run("render '" + scene.string() + "' --no-progress " + flags + " -o '" + out.string() + "'");
    const size_t open = r.err.find(".png ("), close = r.err.find(')', open);
    return r.code == 0 && open != std::string::npos ? r.err.substr(open + 6, close - open - 6) : "";
}

/// The scene file kSmallScene with its `render` size replaced by `size` (e.g. "\"width\": 40").
fs::path small_scene_sized(const std::string& name, const std::string& size) {
    const std::string file_size = "\"width\": 24, \"height\": 16";
    std::string text = kSmallScene;
    text.replace(text.find(file_size), file_size.size(), size);
    return write_scene_file(name, text);
}

// docs/cli.md, "Image size": one size flag keeps the aspect ratio of the file's size when the
// file gives both, else the camera's (4:3 for a scene-file camera); two flags are the size.
TEST(Cli, OneSizeFlagKeepsTheAspectRatio) {
    const fs::path both = write_scene_file("size_both.json", kSmallScene);  // 24x16
    EXPECT_EQ(rendered_size(both, ""), "24x16");
    EXPECT_EQ(rendered_size(both, "--width 30"), "30x20");
    EXPECT_EQ(rendered_size(both, "--height 8"), "12x8");
    EXPECT_EQ(rendered_size(both, "--width 30 --height 30"), "30x30");
    EXPECT_EQ(rendered_size(both, "--width 0 --height 8"), "12x8");  // 0 = not given
    // The file gives one dimension: the other follows the camera's aspect, with or without a flag.
    const fs::path width_only = small_scene_sized("size_width.json", "\"width\": 40");
    EXPECT_EQ(rendered_size(width_only, ""), "40x30");
    EXPECT_EQ(rendered_size(width_only, "--height 15"), "20x15");
    EXPECT_EQ(rendered_size(width_only, "--width 20"), "20x15");
    const fs::path height_only = small_scene_sized("size_height.json", "\"height\": 30");
    EXPECT_EQ(rendered_size(height_only, ""), "40x30");
    EXPECT_EQ(rendered_size(height_only, "--width 20"), "20x15");
}

TEST(Cli, BadSceneFileIsOneLineWithLineAndColumn) {
    std::string text = kSmallScene;
    text.replace(text.find("\"radius\""), 8, "\"radios\"");  // line 8 of the file
    const fs::path scene = write_scene_file("typo.json", text);
    Result r = run("render '" + scene.string() + "' --no-progress");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("typo.json:8:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("radius"), std::string::npos) << r.err;  // the did-you-mean suggestion
    // Broken JSON: the line and column of the syntax error.
    const fs::path broken = write_scene_file("broken.json", "{\n  \"version\": 1,\n  \"objects\": [\n}\n");
    r = run("info '" + broken.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("broken.json:4:"), std::string::npos) << r.err;
}

TEST(Cli, BundledSceneFilesRender) {
    for (const char* name : {"whitted1980.json", "transparent_shadows.json", "glass_mirror_room.json", "quadrics.json"}) {
        const fs::path out = fs::temp_directory_path() / (std::string("whitted_cli_") + name + ".png");
        fs::remove(out);
        Result r = run("render '" + std::string(WHITTED_ASSETS_DIR) + "/scenes/" + name +
                       "' --width 40 --height 30 --aa center --no-progress -o '" + out.string() + "'");
        EXPECT_EQ(r.code, 0) << name << ": " << r.err;
        EXPECT_TRUE(fs::exists(out)) << name;
    }
}

// ---- interruption ----

/// SIGINT during a long render: the process ends promptly with 128 + SIGINT, says so, and leaves
/// the image of the finished tiles and its checkpoint, nothing else (no temporary file). Resuming
/// it: tests/cli/test_session_cli.cpp.
TEST(Cli, InterruptedRenderWritesTheFinishedTilesAndACheckpoint) {
    const fs::path dir = fs::temp_directory_path() / ("whitted_cli_sigint_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path out = dir / "never.png";
    const fs::path err = dir.parent_path() / ("whitted_cli_sigint_err_" + std::to_string(::getpid()) + ".txt");
    const std::string scene = std::string(WHITTED_ASSETS_DIR) + "/scenes/glass_mirror_room.json";
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        std::FILE* e = std::freopen(err.c_str(), "w", stderr);
        (void)e;
        ::execl(WHITTED_EXE, WHITTED_EXE, "render", scene.c_str(), "--width", "1600", "--aa", "stratified", "--spp", "64",
                "--no-progress", "-o", out.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // Wait until the scene is loaded and the render has begun (the log line before rendering names
    // the camera; under load, start-up alone can take seconds), then interrupt.
    for (int i = 0; i < 400 && slurp(err).find("camera") == std::string::npos; ++i) ::usleep(50 * 1000);
    ASSERT_NE(slurp(err).find("camera"), std::string::npos) << slurp(err);
    ::usleep(300 * 1000);
    ASSERT_EQ(::kill(pid, SIGINT), 0);
    int status = 0;
    pid_t done = 0;
    for (int i = 0; i < 100 && done == 0; ++i) {  // up to 10 s
        done = ::waitpid(pid, &status, WNOHANG);
        if (done == 0) ::usleep(100 * 1000);
    }
    if (done == 0) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        FAIL() << "whitted did not exit within 10 s of SIGINT";
    }
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 128 + SIGINT);
    const std::string text = slurp(err);
    EXPECT_NE(text.find("interrupted"), std::string::npos) << text;
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path().filename().string());
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files, (std::vector<std::string>{"never.png", "never.png.checkpoint.exr"}));
    fs::remove_all(dir);
    fs::remove(err);
}

/// Starts `whitted render <Box> -o <dir>/out.png` with the write held open for `delay_ms`
/// (WHITTED_TEST_WRITE_DELAY_MS) and returns the child's pid once its temporary file exists.
pid_t start_slow_write(const fs::path& dir, const fs::path& err, int delay_ms) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::FILE* e = std::freopen(err.c_str(), "w", stderr);
        (void)e;
        ::setenv("WHITTED_TEST_WRITE_DELAY_MS", std::to_string(delay_ms).c_str(), 1);
        const std::string out = (dir / "out.png").string();
        ::execl(WHITTED_EXE, WHITTED_EXE, "render", kBox.c_str(), "--width", "32", "--no-progress", "-o", out.c_str(),
                static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // Wait (up to 20 s) for the temporary file: the write is then in progress.
    for (int i = 0; i < 400; ++i) {
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.path().filename().string().rfind(".out.tmp-", 0) == 0) return pid;
        ::usleep(50 * 1000);
    }
    return pid;
}

/// One SIGINT while the image is being written: the write completes (a whole file, never a
/// half-written one), then the run exits with 128 + SIGINT.
TEST(Cli, SigintDuringWriteFinishesTheFileThenExits) {
    const fs::path dir = fs::temp_directory_path() / ("whitted_cli_wr1_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path err = dir.string() + ".err";
    const pid_t pid = start_slow_write(dir, err, 2000);
    ASSERT_GT(pid, 0);
    ::kill(pid, SIGINT);
    EXPECT_EQ(wait_exit(pid, 20.0), 128 + SIGINT);
    EXPECT_TRUE(fs::exists(dir / "out.png"));
    size_t files = 0;
    for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
    EXPECT_EQ(files, 1u) << "only the finished image remains";
    EXPECT_NE(slurp(err).find("before exiting"), std::string::npos) << slurp(err);
    fs::remove_all(dir);
    fs::remove(err);
}

/// A second SIGINT during the write ends the run at once and removes the temporary file.
TEST(Cli, SecondSigintDuringWriteExitsAtOnceAndLeavesNoFile) {
    const fs::path dir = fs::temp_directory_path() / ("whitted_cli_wr2_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path err = dir.string() + ".err";
    const pid_t pid = start_slow_write(dir, err, 30000);
    ASSERT_GT(pid, 0);
    ::kill(pid, SIGINT);
    ::usleep(200 * 1000);
    ::kill(pid, SIGINT);
    // "At once": far sooner than the 30 s the write is held.
    EXPECT_EQ(wait_exit(pid, 5.0), 128 + SIGINT);
    EXPECT_TRUE(fs::is_empty(dir)) << "no image and no temporary file";
    fs::remove_all(dir);
    fs::remove(err);
}

}  // namespace
