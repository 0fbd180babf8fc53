// `whitted render --no-specialize`, the analysis in `whitted info` and in the render log, and
// `whitted bench skip`'s claims (not its timings), end to end through the executable (the way
// tests/cli/test_cli.cpp runs it).
#include <gtest/gtest.h>

#include "tests/support/cli_image.h"
#include "tests/support/cli_util.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::contains;
using whitted::test::num;
using whitted::test::read_csv;
using whitted::test::read_pixels;
using whitted::test::Result;
using whitted::test::run;

fs::path temp_dir(const std::string& name) { return whitted::test::scratch_dir("whitted_skip_cli", name); }

const std::string kScene = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";

TEST(SkipCli, NoSpecializeSelectsTheGeneralKernelWithTheSameImage) {
    const fs::path general = temp_dir("kernels") / "general.exr", special = temp_dir("kernels") / "special.exr";
    const std::string common = "render '" + kScene + "' --width 64 --height 48 --aa adaptive --min-weight 0 --exr-float --no-progress";
    const Result g = run(common + " --no-specialize -o '" + general.string() + "'");
    ASSERT_EQ(g.code, 0) << g.err;
    EXPECT_TRUE(contains(g.err, "skip   general;")) << g.err;
    EXPECT_TRUE(contains(g.err, "kernel: general")) << g.err;
    const Result s = run(common + " -o '" + special.string() + "'");
    ASSERT_EQ(s.code, 0) << s.err;
    EXPECT_TRUE(contains(s.err, "skip   specialised:")) << s.err;
    const std::vector<float> a = read_pixels(general), b = read_pixels(special);
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b);
}

TEST(SkipCli, RenderLogPrintsTheAnalysisAndTheDefaultMinWeight) {
    const fs::path out = temp_dir("log") / "log.png";
    const Result r = run("render '" + kScene + "' --width 32 --height 24 --aa center --no-progress -o '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "analysis: opaque=no recursive=yes mirror=yes transmission=yes")) << r.err;
    EXPECT_TRUE(contains(r.err, "analysis light[0]: reach=")) << r.err;
    EXPECT_TRUE(contains(r.err, "below --min-weight 0.00392157")) << r.err;  // the default, 1/255
}

TEST(SkipCli, InfoPrintsTheAnalysis) {
    const Result r = run("info '" + kScene + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "\nanalysis: opaque=no recursive=yes")) << r.out;
    EXPECT_TRUE(contains(r.out, "\nanalysis memory: triangles=")) << r.out;
    EXPECT_TRUE(contains(r.out, "\nanalysis material[0]: used=yes")) << r.out;
    // Memory per primitive: the spheres' records (at least the Sphere struct each).
    const size_t at = r.out.find("bytes_per_sphere=");
    ASSERT_NE(at, std::string::npos) << r.out;
    EXPECT_GE(std::stod(r.out.substr(at + 17)), double(sizeof(double) * 4)) << r.out;
    EXPECT_FALSE(contains(r.out, " spheres=0 ")) << r.out;
}

TEST(SkipCli, RenderPrintsAcceleratorBytesPerPrimitive) {
    const fs::path out = temp_dir("accel_bytes") / "a.png";
    const Result r = run("render '" + kScene + "' --width 16 --height 12 --aa center --no-progress -o '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    const size_t at = r.err.find(" B per primitive)");
    ASSERT_NE(at, std::string::npos) << r.err;
    const size_t open = r.err.rfind('(', at);
    EXPECT_GT(std::stod(r.err.substr(open + 1)), 0.0) << r.err;
}

// bench skip on a small render: the specialised kernel's image equals the general one at
// min_weight 0 (whole render and camera pass), the min-weight sweep only removes secondary rays,
// and the Whitted overhead replays exactly the rays the render counted.
TEST(SkipCli, BenchSkipReplaysTheRaysTheRenderCounted) {
    const fs::path out = temp_dir("bench");
    const Result r = run("bench skip '" + kScene + "' --width 96 --repeat 2 --threads 1 --no-plot --no-packets -o '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(contains(r.out, "(median of 2 render/replay pairs;")) << r.out;

    const auto rows = read_csv(out / "skip.csv");
    ASSERT_EQ(rows.size(), 2u + 6u);  // general and specialised, then the default sweep without its 0
    std::map<std::string, std::string> at_default;
    double last_min_weight = 0.0, last_secondary = 1e300;
    for (size_t i = 0; i < rows.size(); ++i) {
        const auto& row = rows[i];
        ASSERT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(num(row, "total"), num(row, "camera") + num(row, "shadow") + num(row, "secondary"));
        EXPECT_EQ(num(row, "secondary"), num(row, "reflection") + num(row, "refraction"));
        if (i < 2) {
            // The specialisation skips only work that contributes 0: the same image, the same rays.
            EXPECT_EQ(row.at("variant"), i == 0 ? "general" : "specialised");
            EXPECT_EQ(num(row, "differing_pixels"), 0.0) << row.at("variant");
            EXPECT_EQ(num(row, "total"), num(rows[0], "total"));
            continue;
        }
        // A larger cutoff traces a subset of the rays a smaller one traces.
        EXPECT_GT(num(row, "min_weight"), last_min_weight);
        EXPECT_LE(num(row, "secondary"), last_secondary) << row.at("min_weight");
        EXPECT_EQ(num(row, "camera"), num(rows[0], "camera"));
        last_min_weight = num(row, "min_weight");
        last_secondary = num(row, "secondary");
        if (row.at("min_weight") == "0.00392157") at_default = row;
    }
    EXPECT_LT(last_secondary, num(rows[0], "secondary"));  // whitted1980 has mirrors and glass
    ASSERT_FALSE(at_default.empty());

    // The overhead's recorded rays are the rays a render at the CLI default min_weight counts.
    const auto overhead = read_csv(out / "skip_overhead.csv");
    ASSERT_EQ(overhead.size(), 1u);
    const auto& o = overhead[0];
    ASSERT_EQ(o.count("_bad"), 0u) << o.at("_bad");
    for (const char* kind : {"camera", "shadow", "secondary"}) EXPECT_EQ(num(o, kind), num(at_default, kind)) << kind;
    EXPECT_EQ(num(o, "rays"), num(at_default, "total"));
    EXPECT_NEAR(num(o, "render_mrays"), num(o, "rays") / num(o, "render_s") * 1e-6, 0.01 * num(o, "render_mrays"));
    EXPECT_NEAR(num(o, "replay_mrays"), num(o, "rays") / num(o, "replay_s") * 1e-6, 0.01 * num(o, "replay_mrays"));
    EXPECT_GT(num(o, "overhead_ratio"), 0.0);
    // The traversal is a part of the render (one thread), and the decorator saw the replay's queries.
    EXPECT_GT(num(o, "render_traversal_share"), 0.0);
    EXPECT_LT(num(o, "render_traversal_share"), 1.0);
    EXPECT_GT(num(o, "traversal_render_over_replay"), 0.0);
    EXPECT_TRUE(contains(r.out, "traversal inside the render: ")) << r.out;

    // The camera pass: ray by ray and in packets, the specialised kernel gives the general image.
    const auto pass = read_csv(out / "skip_camera_pass.csv");
    ASSERT_GE(pass.size(), 3u);
    for (const auto& row : pass) {
        ASSERT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(num(row, "differing_pixels"), 0.0) << row.at("variant");
    }
}

}  // namespace
