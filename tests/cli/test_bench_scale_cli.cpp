// `whitted bench scale` end to end through the executable at tiny sizes: the CSV's columns, one
// row per kind and size, the primitive counts of the generated scenes (n spheres; n nodes of a
// 4-triangle tetrahedron each) and positive memory figures. No time is checked.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <algorithm>
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

TEST(BenchScaleCli, CsvRowsPerKindAndSizeWithPrimitiveCounts) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_scale_cli", "sweep");
    const Result r = run("bench scale --sizes 10,200 --width 8 --threads 1 --no-plot --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    std::vector<std::string> header;
    const std::vector<Row> rows = read_csv(out / "scale.csv", &header);
    for (const char* column : {"kind", "objects", "primitives", "file_bytes", "load_seconds", "build_seconds",
                               "render_seconds", "peak_bytes", "peak_bytes_per_object", "accel_bytes",
                               "accel_bytes_per_primitive"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(rows.size(), 4u);
    for (const Row& row : rows) {
        EXPECT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        const double n = num(row, "objects");
        EXPECT_EQ(num(row, "primitives"), row.at("kind") == "spheres" ? n : 4 * n) << row.at("kind");
        EXPECT_GT(num(row, "file_bytes"), 0.0);
        EXPECT_GT(num(row, "accel_bytes"), 0.0);
        EXPECT_GE(num(row, "load_seconds"), 0.0);
    }
    EXPECT_EQ(rows[0].at("kind"), "spheres");
    EXPECT_EQ(rows[3].at("kind"), "nodes");
    EXPECT_EQ(num(rows[3], "objects"), 200.0);
    // The generated files are removed unless --keep.
    for (const auto& e : fs::directory_iterator(out)) EXPECT_EQ(e.path().extension(), ".csv") << e.path();
}

TEST(BenchScaleCli, ZeroObjectsIsOneErrorLine) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_scale_cli", "bad");
    const Result r = run("bench scale --sizes 10,0 --no-plot --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("--sizes"), std::string::npos) << r.err;
}

}  // namespace
