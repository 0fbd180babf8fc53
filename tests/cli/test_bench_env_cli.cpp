// `whitted bench env` end to end through the executable, on one small asset, one map and two
// light counts at a tiny size: the CSVs' columns, the reference row's zero error, finite errors,
// and a printed default that is one of the counts compared. No time is checked.
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

const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";
const std::string kScene = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";

TEST(BenchEnvCli, CsvColumnsReferenceRowAndAListedDefault) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_env_cli", "sweep");
    const Result r = run("bench env '" + kBox + "' --maps studio --lights 0,16 --reference 16 --width 24 --repeat 1 "
                         "--threads 1 --overhead-scenes '" + kScene + "' --overhead-repeat 1 --split-maps studio,courtyard "
                         "--split-counts 4,16 --split-normals 8 --occlusion 0,4 --occlusion-reference 16 --occlusion-maps furnace "
                         "--no-plot --out '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;

    std::vector<std::string> header;
    const std::vector<Row> rows = read_csv(out / "env.csv", &header);
    for (const char* column : {"asset", "map", "lights", "extracted_lights", "reference", "rmse_display",
                               "rmse_display_codes", "rmse_linear", "seconds", "timing", "runs", "shadow_rays"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].at("lights"), "0");
    EXPECT_EQ(rows[1].at("lights"), "16");
    for (const Row& row : rows) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(row.at("asset"), "Box");
        EXPECT_EQ(row.at("map"), "studio");
        EXPECT_TRUE(std::isfinite(num(row, "rmse_display"))) << row.at("rmse_display");
        EXPECT_TRUE(std::isfinite(num(row, "rmse_linear"))) << row.at("rmse_linear");
        EXPECT_GE(num(row, "rmse_display"), 0.0);
        EXPECT_LE(num(row, "rmse_display"), 1.0);
    }
    EXPECT_EQ(num(rows[1], "rmse_display"), 0.0);  // the reference against itself
    EXPECT_EQ(num(rows[0], "shadow_rays"), 0.0);   // no extracted light, no shadow ray
    EXPECT_GT(num(rows[1], "extracted_lights"), 0.0);

    const std::string key = "chosen default --env-lights: ";
    const size_t at = r.out.find(key);
    ASSERT_NE(at, std::string::npos) << r.out;
    const int chosen = std::stoi(r.out.substr(at + key.size()));
    EXPECT_TRUE(chosen == 0 || chosen == 16) << chosen;
    // The choice follows the CSV: 0 only when it is within one code of the reference.
    if (chosen == 0) {
        EXPECT_LE(num(rows[0], "rmse_display"), 1.0 / 255.0);
    }

    const std::vector<Row> overhead = read_csv(out / "env_overhead.csv", &header);
    for (const char* column : {"scene", "map", "plain_seconds", "env_seconds", "ratio", "lights"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(overhead.size(), 1u);
    EXPECT_EQ(overhead[0].at("scene"), "whitted1980");
    EXPECT_TRUE(std::isfinite(num(overhead[0], "ratio")));
    EXPECT_EQ(overhead[0].at("plain_total_rays"), overhead[0].at("env_total_rays"));  // lookups only, no extra ray

    // The occlusion sweep: the generated scene and default.glb under the furnace, budgets 0, 4 and
    // the reference 16; off traces no occlusion ray, the reference matches itself.
    EXPECT_TRUE(fs::exists(out / "occlusion.glb"));
    const std::vector<Row> occ = read_csv(out / "env_occlusion.csv", &header);
    for (const char* column : {"scene", "map", "budget", "psnr_display", "mean_ratio", "psnr_previous", "seconds",
                               "occlusion_rays"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(occ.size(), 6u);
    EXPECT_EQ(occ[0].at("scene"), "occlusion");
    EXPECT_EQ(occ[3].at("scene"), "default");
    EXPECT_EQ(occ[0].at("budget"), "0");
    EXPECT_EQ(num(occ[0], "occlusion_rays"), 0.0);
    EXPECT_GT(num(occ[1], "occlusion_rays"), 0.0);
    EXPECT_EQ(occ[2].at("psnr_display"), "inf");
    EXPECT_LT(num(occ[0], "psnr_display"), num(occ[1], "psnr_display"));  // occlusion off is the farthest
    EXPECT_NE(r.out.find("chosen: "), std::string::npos) << r.out;

    // The split alone: a cost row per map, an error row per threshold rule and count (8 rules with the
    // ambient correction, the default rule without), errors finite and the default rule's small.
    const std::vector<Row> cost = read_csv(out / "env_split_cost.csv", &header);
    ASSERT_EQ(cost.size(), 2u);
    EXPECT_EQ(cost[0].at("map"), "studio");
    EXPECT_GT(num(cost[1], "bytes"), 0.0);
    const std::vector<Row> split = read_csv(out / "env_split.csv", &header);
    for (const char* column : {"factor", "correct_ambient", "lights", "axes_worst_studio_courtyard_pct",
                               "random_max_all_pct", "random_rms_all_pct"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(split.size(), 9u * 2u);
    for (const Row& row : split) EXPECT_TRUE(std::isfinite(num(row, "random_rms_all_pct"))) << row.at("factor");
    EXPECT_EQ(split[0].at("factor"), "2/sqrt(n)");
    EXPECT_EQ(split[0].at("correct_ambient"), "yes");
    EXPECT_LT(num(split[1], "random_max_all_pct"), 25.0);  // 16 lights, the default rule: 14.8 % over the six maps
}

// --path-reference: the occlusion sweep's budgets against the path tracer on the generated scene
// (default.glb has punctual lights: said and skipped), a row per budget, the targets line.
TEST(BenchEnvCli, PathReferenceComparesEveryBudget) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_env_cli", "path");
    const Result r = run("bench env '" + kBox + "' --maps studio --lights 0 --reference 0 --width 32 --repeat 1 "
                         "--no-overhead --no-split --no-plot --occlusion 0,25 --occlusion-reference 64 "
                         "--occlusion-maps furnace --path-reference 16 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    std::vector<std::string> header;
    const std::vector<Row> rows = read_csv(out / "env_path_reference.csv", &header);
    for (const char* column : {"scene", "map", "budget", "path_spp", "psnr_display", "mean_ratio", "seconds",
                               "path_seconds", "time_ratio"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(rows.size(), 3u);  // budgets 0, 25 (the default) and 64 on the generated scene only
    for (const Row& row : rows) {
        EXPECT_EQ(row.at("scene"), "occlusion");
        EXPECT_GT(num(row, "psnr_display"), 15.0);
        EXPECT_GT(num(row, "mean_ratio"), 0.8);
        EXPECT_LT(num(row, "mean_ratio"), 1.2);
        EXPECT_GT(num(row, "path_seconds"), 0.0);
    }
    EXPECT_NE(r.out.find("targets at budget 25: mean"), std::string::npos) << r.out;  // kDefaultEnvOcclusion
    EXPECT_NE(r.out.find("path tracer: not run (the scene has 3 punctual light(s)"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(out / "occlusion-occlusion-furnace-path16.png"));
}

TEST(BenchEnvCli, NegativeCountIsOneErrorLine) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_env_cli", "bad");
    const Result r = run("bench env '" + kBox + "' --lights 0,-1 --width 16 --no-plot --no-overhead --out '" + out.string() + "'");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("--lights"), std::string::npos) << r.err;
}

}  // namespace
