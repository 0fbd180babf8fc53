// `whitted bench aa` end to end through the executable: the sweep's ray counts, and the target's
// threshold search (--target-search), whose every step must be the geometric mean of the bracket
// the runs before it leave, and whose reported setting must reach stratified 16's display RMSE.
// A 64 px Box keeps it under a second; no time is checked, only what the bench claims.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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

fs::path temp_dir(const std::string& name) { return whitted::test::scratch_dir("whitted_bench_aa_cli", name); }

const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";

Result bench(const fs::path& out, int steps) {
    return run("bench aa '" + kBox + "' --width 64 --ref-spp 64 --repeat 1 --threads 1 --no-plot --target-search " +
               std::to_string(steps) + " --out '" + out.string() + "' --cache '" + (out / "cache").string() + "'");
}

/// The bench's label rounding: three significant digits.
float round3(double t) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", t);
    return std::stof(buf);
}

TEST(BenchAaCli, SweepCountsAndABisectingThresholdSearch) {
    const fs::path out = temp_dir("search");
    const Result r = bench(out, 3);
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<Row> sweep = read_csv(out / "aa.csv");
    const std::vector<Row> searched = read_csv(out / "aa_target_search.csv");
    // center, corners, 3 depths x 6 thresholds, 6 stratified box, 3 tent.
    ASSERT_EQ(sweep.size(), 29u);
    const Row* s16 = nullptr;
    for (const Row& row : sweep) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        const long cam = std::stol(row.at("camera_rays"));
        if (row.at("mode") == "center") {
            EXPECT_EQ(cam, 64 * 48);
        } else if (row.at("mode") == "corners") {
            EXPECT_EQ(cam, 65 * 49);  // the shared lattice
        } else if (row.at("mode") == "stratified") {
            EXPECT_EQ(cam, std::stol(row.at("spp")) * 64 * 48);
        }
        if (row.at("label") == "stratified 16 spp box") s16 = &row;
    }
    ASSERT_NE(s16, nullptr);
    const double target = num(*s16, "rmse_display");

    // Replay the bisection from the sweep: per depth, the bracket (largest passing threshold, the
    // next larger failing one), then each searched run halves it at the rounded geometric mean.
    ASSERT_FALSE(searched.empty()) << "no depth had a bracket to narrow: the test scene no longer exercises the search\n"
                                   << r.out;
    std::map<int, std::pair<float, float>> bracket;  // depth -> (pass, fail)
    for (const Row& row : sweep) {
        if (row.at("mode") != "adaptive" || num(row, "rmse_display") > target) continue;
        auto& b = bracket[std::stoi(row.at("depth"))];
        b.first = std::max(b.first, float(num(row, "threshold")));
    }
    for (auto& [d, b] : bracket)
        for (const Row& row : sweep)
            if (row.at("mode") == "adaptive" && std::stoi(row.at("depth")) == d && num(row, "threshold") > b.first &&
                num(row, "rmse_display") > target && (b.second == 0.f || num(row, "threshold") < b.second))
                b.second = float(num(row, "threshold"));
    std::map<int, int> steps;
    for (const Row& row : searched) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(row.at("mode"), "adaptive");
        const int d = std::stoi(row.at("depth"));
        ASSERT_TRUE(bracket.count(d) && bracket[d].second > 0.f) << "searched depth " << d << " had no bracket";
        auto& [pass, fail] = bracket[d];
        const float t = float(num(row, "threshold"));
        EXPECT_FLOAT_EQ(t, round3(std::sqrt(double(pass) * double(fail)))) << "depth " << d;
        EXPECT_GT(t, pass);
        EXPECT_LT(t, fail);
        (num(row, "rmse_display") <= target ? pass : fail) = t;
        EXPECT_LE(++steps[d], 3) << "depth " << d;
    }

    // The reported setting reaches the target, whichever file it comes from.
    const std::string key = "(threshold search): ";
    const size_t at = r.out.find(key);
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::string label = r.out.substr(at + key.size(), r.out.find(" at ", at) - at - key.size());
    const Row* best = nullptr;
    for (const std::vector<Row>* rows : {&sweep, &searched})
        for (const Row& row : *rows)
            if (row.at("label") == label) best = &row;
    ASSERT_NE(best, nullptr) << label;
    EXPECT_LE(num(*best, "rmse_display"), target) << label;
}

TEST(BenchAaCli, NoSearchWithZeroSteps) {
    const fs::path out = temp_dir("none");
    const Result r = bench(out, 0);
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(read_csv(out / "aa_target_search.csv").empty());
    EXPECT_EQ(r.out.find("(threshold search)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("target adaptive <= 1/3 time of stratified 16"), std::string::npos) << r.out;
}

// --only runs the labelled settings; an adaptive label outside the sweep (as the search prints
// them) is run too, and anything else is one error line and a non-zero exit.
TEST(BenchAaCli, OnlyRunsTheLabelledSettingsIncludingSearchedThresholds) {
    const fs::path out = temp_dir("only");
    const std::string common = "bench aa '" + kBox + "' --width 32 --ref-spp 4 --repeat 1 --threads 1 --no-plot --out '" +
                               out.string() + "' --cache '" + (out / "cache").string() + "' ";
    const Result r = run(common + "--only 'adaptive t=0.0595 d=2' --only 'stratified 16 spp box'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<Row> rows = read_csv(out / "aa.csv");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].at("label"), "stratified 16 spp box");
    EXPECT_EQ(rows[1].at("label"), "adaptive t=0.0595 d=2");
    EXPECT_FLOAT_EQ(float(num(rows[1], "threshold")), 0.0595f);
    EXPECT_EQ(rows[1].at("depth"), "2");

    for (const char* bad : {"adaptive t=0.05 d=9", "stratified 17 spp box", "adaptive t=0.05 d=2 "}) {
        const Result e = run(common + "--only '" + bad + "'");
        EXPECT_NE(e.code, 0) << bad;
        EXPECT_NE(e.err.find(std::string("--only '") + bad + "': no such setting"), std::string::npos) << e.err;
        EXPECT_LE(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
    }
}

}  // namespace
