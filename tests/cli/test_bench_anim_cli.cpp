// `whitted bench anim` end to end through the executable at tiny sizes: a row per scene and
// accelerator, the deforming mesh found and refitted, the updated accelerator agreeing with a new
// one on every checked ray, and the sequence's totals adding up. No time is checked.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::num;
using whitted::test::read_csv;
using whitted::test::Result;
using whitted::test::run;

using Row = std::map<std::string, std::string>;

TEST(BenchAnimCli, RowsPerSceneAndAccelRefitAgreesWithARebuild) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_anim_cli", "small");
    const Result r = run("bench anim --triangles 2000 --frames 3 --cesium-frames 3 --rebuild-frames 2 --check-rays 512 "
                         "--width 32 --height 18 --sequence-frames 3 --sequence-width 32 --sequence-height 18 "
                         "--threads 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;

    std::vector<std::string> header;
    const std::vector<Row> rows = read_csv(out / "anim.csv", &header);
    for (const char* column : {"scene", "triangles", "deforming_meshes", "accel", "update_median_seconds",
                               "rebuild_load_build_median_seconds", "render_seconds", "update_render_ratio",
                               "accel_update", "check_rays", "check_mismatches"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(rows.size(), 4u);  // {CesiumMan, generated} x {embree, bvh}
    for (const Row& row : rows) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(num(row, "deforming_meshes"), 1.0) << row.at("scene");
        EXPECT_EQ(row.at("accel_update"), "refit") << row.at("scene") << " " << row.at("accel");
        EXPECT_GT(num(row, "refit_frames"), 0.0);
        EXPECT_GT(num(row, "check_rays"), 0.0);
        EXPECT_EQ(num(row, "check_mismatches"), 0.0) << row.at("scene") << " " << row.at("accel");
        EXPECT_TRUE(std::isfinite(num(row, "update_render_ratio")));
        EXPECT_GE(num(row, "update_median_seconds"), 0.0);
    }
    EXPECT_EQ(rows[0].at("scene"), "CesiumMan");
    EXPECT_EQ(num(rows[0], "triangles"), 4672.0);
    EXPECT_EQ(rows[2].at("scene"), "generated");
    EXPECT_GT(num(rows[2], "triangles"), 1500.0);
    EXPECT_LT(num(rows[2], "triangles"), 2500.0);

    const std::vector<Row> sequence = read_csv(out / "anim_sequence.csv", &header);
    ASSERT_EQ(sequence.size(), 2u);
    for (const Row& row : sequence) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        // The total holds the renders and everything else, so the ratio is at least one.
        EXPECT_GE(num(row, "ratio"), 1.0);
        EXPECT_TRUE(std::isfinite(num(row, "ratio")));
    }
    // The generated mesh is removed unless --keep.
    for (const auto& e : fs::directory_iterator(out)) EXPECT_EQ(e.path().extension(), ".csv") << e.path();
}

TEST(BenchAnimCli, UnknownSceneIsOneErrorLine) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_anim_cli", "bad");
    const Result r = run("bench anim --scenes bogus --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("unknown scene 'bogus'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("cesium, generated"), std::string::npos) << r.err;
}

}  // namespace
