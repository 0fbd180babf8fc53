// `whitted bench accel` end to end through the executable (the way tests/cli/test_cli.cpp runs
// it): rays recorded from a real render (generated scenes with the bench material, a scene file
// with its own materials), every backend validated against brute force, the CSV columns, the
// 5M-style size rule and the budget's "skipped" notices, and --ratio. Small sizes and few rays:
// the figures themselves are not checked (no timing assertions), only what the bench claims
// about them.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::contains;
using whitted::test::read_csv;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::slurp;

fs::path temp_dir(const std::string& name) { return whitted::test::scratch_dir("whitted_bench_accel_cli", name); }

const std::string kWhitted1980 = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";

TEST(BenchAccelCli, RecordsARendersRaysAndValidatesEveryBackend) {
    const fs::path out = temp_dir("main");
    const Result r = run("bench accel --scenes spheres,'" + kWhitted1980 +
                         "' --sizes 1000,3000 --accel embree,bvh,grid --threads 1 --rays 1024 --budget 2 -o '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    // The generated scene is rendered at 32x32 (one camera ray per pixel) with the bench
    // material, so it has secondary rays; the scene file keeps its own camera (800x600 -> 32x24).
    EXPECT_TRUE(contains(r.out, "spheres, 1920 triangles: recorded from a 32x32 render: camera 1024")) << r.out;
    EXPECT_TRUE(contains(r.out, "whitted1980, 2 triangles: recorded from a 32x24 render: camera 768")) << r.out;
    EXPECT_FALSE(contains(r.out, "UNTRUSTED")) << r.out;

    std::vector<std::string> header;
    const auto rows = read_csv(out / "accel.csv", &header);
    const std::vector<std::string> expected{"scene", "triangles", "accel", "build_s", "bytes_per_tri", "nodes", "sah",
                                            "threads", "camera_rays", "shadow_rays", "secondary_rays", "camera_mrays",
                                            "shadow_mrays", "secondary_mrays", "validated_against", "mismatch_fraction",
                                            "near_origin_fraction", "load"};
    EXPECT_EQ(header, expected);
    // 2 sizes x 3 backends for the generator, 3 backends for the scene file.
    ASSERT_EQ(rows.size(), 9u);
    std::map<std::string, int> per_scene;
    for (const auto& row : rows) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        ++per_scene[row.at("scene")];
        EXPECT_EQ(row.at("validated_against"), "brute");
        EXPECT_LE(std::stod(row.at("mismatch_fraction")), 1e-3) << row.at("scene") << " " << row.at("accel");
        // Every ray kind was recorded from the render and replayed; the thinned sets are at most
        // --rays long.
        for (const char* kind : {"camera", "shadow", "secondary"}) {
            const long n = std::stol(row.at(std::string(kind) + "_rays"));
            EXPECT_GT(n, 0) << kind << " " << row.at("scene");
            EXPECT_LE(n, 1024) << kind << " " << row.at("scene");
            EXPECT_GT(std::stod(row.at(std::string(kind) + "_mrays")), 0.0) << kind << " " << row.at("scene");
        }
    }
    EXPECT_EQ(per_scene["spheres"], 6);
    EXPECT_EQ(per_scene["whitted1980"], 3);
    // The recording is the same rays whatever the backend: one set per scene and size.
    for (const auto& a : rows)
        for (const auto& b : rows)
            if (a.at("scene") == b.at("scene") && a.at("triangles") == b.at("triangles")) {
                for (const char* col : {"camera_rays", "shadow_rays", "secondary_rays"}) EXPECT_EQ(a.at(col), b.at(col));
            }
}

TEST(BenchAccelCli, LargeSizesRunOnlyEmbreeAndBvhAndSaySo) {
    const fs::path out = temp_dir("large");
    // 2M triangles > the 1.5M limit: grid is skipped before anything is built or recorded.
    const Result r = run("bench accel --scenes soup --sizes 2000000 --accel grid --threads 1 --rays 256 -o '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(contains(r.out, "skipped: soup 2000000 grid: > 1.5M triangles run for embree and bvh only")) << r.out;
    EXPECT_FALSE(contains(r.out, "recorded from")) << r.out;
    EXPECT_TRUE(read_csv(out / "accel.csv").empty());
}

TEST(BenchAccelCli, CellsPredictedPastTheBudgetAreSkippedAndListed) {
    const fs::path out = temp_dir("budget");
    // The first size always runs (nothing to predict from); the octree's build there, scaled to 20x
    // the triangles, is far past a 1 ms budget.
    const Result r = run("bench accel --scenes terrain --sizes 1000,20000 --accel bvh,octree --threads 1 --rays 256 "
                         "--budget 0.001 -o '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(contains(r.out, "skipped: terrain 20000 octree: predicted build")) << r.out;
    EXPECT_TRUE(contains(r.out, "skipped: terrain 20000 bvh: predicted build")) << r.out;
    EXPECT_TRUE(contains(r.out, "2 cells skipped (listed above)")) << r.out;
    const auto rows = read_csv(out / "accel.csv");
    ASSERT_EQ(rows.size(), 2u);  // bvh and octree at the first size only
    for (const auto& row : rows) EXPECT_EQ(row.at("triangles"), "968");
}

TEST(BenchAccelCli, RatioModeComparesEveryRayKindWithTheFirstBackend) {
    const fs::path out = temp_dir("ratio");
    const Result r = run("bench accel --ratio --scenes terrain --sizes 1000 --accel bvh,grid --rays 1024 --repeats 1 -o '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const auto rows = read_csv(out / "ratio.csv");
    ASSERT_EQ(rows.size(), 6u);  // 2 backends x 3 ray kinds
    std::map<std::string, int> kinds;
    for (const auto& row : rows) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        ++kinds[row.at("kind")];
        EXPECT_GT(std::stol(row.at("rays")), 0) << row.at("kind");
        EXPECT_GT(std::stod(row.at("ns_per_ray_median")), 0.0) << row.at("kind");
        EXPECT_LE(std::stod(row.at("mismatch_fraction")), 1e-3);
        if (row.at("accel") == "bvh") {
            EXPECT_EQ(row.at("ratio_median"), "1.0000");  // the first backend
        }
    }
    EXPECT_EQ(kinds, (std::map<std::string, int>{{"camera", 2}, {"secondary", 2}, {"shadow", 2}}));
}

TEST(BenchAccelCli, UnknownSceneIsAnError) {
    const Result r = run("bench accel --scenes cube --sizes 1000 --accel bvh --threads 1 -o '" +
                         temp_dir("error").string() + "'");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(contains(r.err, "unknown scene 'cube'")) << r.err;
}

}  // namespace
