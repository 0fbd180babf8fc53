// `whitted bench materials` end to end through the executable at a tiny size: a row per material
// extension, each with a finite positive time ratio and an image that the extension changes. No
// time is checked against the target.
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

const std::vector<std::string> kExtensions{"clearcoat",  "sheen",                "iridescence",        "anisotropy",
                                           "dispersion", "diffuse_transmission", "specular_glossiness"};

TEST(BenchMaterialsCli, EveryExtensionHasARowAndChangesItsImage) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_materials_cli", "small");
    const Result r = run("bench materials --width 32 --height 24 --repeat 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;

    std::vector<std::string> header;
    const std::vector<Row> rows = read_csv(out / "materials.csv", &header);
    for (const char* column : {"extension", "sample", "kernel_with", "kernel_without", "seconds_with", "seconds_without",
                               "ratio", "ratio_per_ray", "shadow_with", "shadow_without", "mean_abs_diff"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
    ASSERT_EQ(rows.size(), kExtensions.size());
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row& row = rows[i];
        ASSERT_EQ(row.count("_bad"), 0u) << row.at("_bad");
        EXPECT_EQ(row.at("extension"), kExtensions[i]);
        const double ratio = num(row, "ratio");
        EXPECT_TRUE(std::isfinite(ratio)) << row.at("extension");
        EXPECT_GT(ratio, 0.0) << row.at("extension");
        // One run: its pair's ratio; per ray: the same over the rays each side traced.
        EXPECT_NEAR(ratio, num(row, "seconds_with") / num(row, "seconds_without"), 2e-2 * ratio) << row.at("extension");
        const double per_ray = ratio * num(row, "total_without") / num(row, "total_with");
        EXPECT_NEAR(num(row, "ratio_per_ray"), per_ray, 1e-3 * per_ray) << row.at("extension");
        EXPECT_GT(num(row, "materials_with"), 0.0) << row.at("extension");
        // The extension visibly changes its sample.
        EXPECT_GT(num(row, "mean_abs_diff"), 0.0) << row.at("extension");
        EXPECT_GT(num(row, "camera_with"), 0.0) << row.at("extension");
    }
    // The bundled samples where they exist, generated ones for the rest.
    EXPECT_NE(rows[0].at("sample").find("ClearCoatTest.glb"), std::string::npos) << rows[0].at("sample");
    EXPECT_EQ(num(rows[0], "generated"), 0.0);
    EXPECT_EQ(num(rows[1], "generated"), 1.0);
    EXPECT_TRUE(fs::exists(out / "sheen.glb"));
    // A layered extension runs the layered kernel, which its removal leaves.
    EXPECT_NE(rows[1].at("kernel_with").find("layered"), std::string::npos) << rows[1].at("kernel_with");
    EXPECT_EQ(rows[1].at("kernel_without").find("layered"), std::string::npos) << rows[1].at("kernel_without");
}

TEST(BenchMaterialsCli, GeneratedFallbacksChangeTheirImages) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_materials_cli", "generated");
    const Result r = run("bench materials --generated --only clearcoat,anisotropy --width 16 --height 12 --repeat 1 "
                         "--out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<Row> rows = read_csv(out / "materials.csv");
    ASSERT_EQ(rows.size(), 2u);
    for (const Row& row : rows) {
        EXPECT_EQ(num(row, "generated"), 1.0);
        EXPECT_GT(num(row, "materials_with"), 0.0) << row.at("extension");
        EXPECT_GT(num(row, "mean_abs_diff"), 0.0) << row.at("extension");
    }
}

TEST(BenchMaterialsCli, UnknownExtensionIsOneErrorLine) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_materials_cli", "bad");
    const Result r = run("bench materials --only bogus --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("unknown extension 'bogus'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("clearcoat"), std::string::npos) << r.err;
}

}  // namespace
