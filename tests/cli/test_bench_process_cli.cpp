// `whitted bench process`'s claims, not its timings: every row is a complete run that succeeded,
// the split of a render adds up to its wall time, the CSV holds what the table printed, and bad
// options are one clear error.
#include <gtest/gtest.h>

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
using whitted::test::Result;
using whitted::test::run;

const std::string kScene = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";
const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";

TEST(BenchProcessCli, RowsAreCompleteRunsAndTheSplitAddsUp) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_process", "rows");
    const Result r = run("bench process '" + kScene + "' '" + kBox +
                         "' --repeat 1 --sizes 24x16 --formats png,exr --threads 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = read_csv(out / "process.csv");
    // --help, info, the scene at 24x16 in two formats, Box at 64x64 in two formats.
    ASSERT_EQ(rows.size(), 6u) << r.out;
    EXPECT_EQ(rows[0].at("run"), "--help");
    EXPECT_EQ(rows[1].at("run"), "info whitted1980.json");
    size_t renders = 0;
    for (const auto& row : rows) {
        const double wall = num(row, "wall_seconds");
        EXPECT_GT(wall, 0.0);
        EXPECT_LE(num(row, "wall_min_seconds"), wall);
        EXPECT_GT(num(row, "peak_bytes"), 1e6);
        if (row.at("run").rfind("render ", 0) != 0) continue;
        ++renders;
        const double parts = num(row, "startup_exit_seconds") + num(row, "load_seconds") + num(row, "build_seconds") +
                             num(row, "render_seconds") + num(row, "write_seconds");
        EXPECT_NEAR(parts, wall, 0.002 + 1e-3 * wall) << row.at("run");  // the summary rounds to milliseconds
        EXPECT_GT(num(row, "render_seconds"), 0.0);
        EXPECT_EQ(row.at("size"), row.at("scene") == kBox ? "64x64" : "24x16");
    }
    EXPECT_EQ(renders, 4u);
    EXPECT_TRUE(contains(r.out, "render Box.glb")) << r.out;
    // The images are removed after measuring: the output folder holds the CSV only.
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(out)) files += e.is_regular_file();
    EXPECT_EQ(files, 1u);
    fs::remove_all(out);
}

TEST(BenchProcessCli, BadOptionsAreOneClearError) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_process", "bad");
    Result r = run("bench process '" + kScene + "' --sizes 12 --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.err, "'12' is not WxH")) << r.err;
    r = run("bench process '" + kScene + "' --formats bmp --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.err, "'bmp'")) << r.err;
    r = run("bench process /no/such/scene.json --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.err, "/no/such/scene.json: no such file")) << r.err;
    fs::remove_all(out);
}

}  // namespace
