// `whitted bench quadrics` end to end through the executable at a tiny size: a row per scene and
// mode, the analytic row with no tessellation and an exact PSNR against itself, finer
// tessellations closer to the analytic image than coarser ones, images written. No time is checked.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

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

TEST(BenchQuadricsCli, RowsPerSceneAndModeErrorFallsWithSegments) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_quadrics_cli", "small");
    const Result r = run("bench quadrics --size 1 --segments 6,48 --width 48 --height 48 --repeat 1 --threads 1 --out '" +
                         out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<std::map<std::string, std::string>> rows = read_csv(out / "quadrics.csv");
    ASSERT_EQ(rows.size(), 6u);  // {rings, tree} x {analytic, 6, 48}
    for (size_t s = 0; s < 2; ++s) {
        const auto& analytic = rows[3 * s];
        const auto& coarse = rows[3 * s + 1];
        const auto& fine = rows[3 * s + 2];
        EXPECT_EQ(analytic.at("mode"), "analytic");
        EXPECT_EQ(analytic.at("triangles"), "0");
        EXPECT_GT(num(analytic, "quadrics"), 10.0);
        EXPECT_TRUE(std::isinf(num(analytic, "psnr_display")));
        EXPECT_EQ(fine.at("quadrics"), "0");
        EXPECT_GT(num(fine, "triangles"), num(coarse, "triangles"));
        EXPECT_GT(num(fine, "psnr_display"), num(coarse, "psnr_display")) << analytic.at("scene");
        EXPECT_GT(num(analytic, "total_rays"), 48.0 * 48.0);
    }
    EXPECT_TRUE(fs::exists(out / "rings-analytic.png"));
    EXPECT_TRUE(fs::exists(out / "tree-48-segments.png"));
    const Result bad = run("bench quadrics --scenes teapot --repeat 1 --width 8 --height 8 --out '" + out.string() + "'");
    EXPECT_EQ(bad.code, 1);
    EXPECT_NE(bad.err.find("unknown SPD scene 'teapot'"), std::string::npos) << bad.err;
}

}  // namespace
