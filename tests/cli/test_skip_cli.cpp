// `whitted render --no-specialize`, the analysis in `whitted info` and in the render log, end to
// end through the executable (the way tests/cli/test_cli.cpp runs it).
#include <gtest/gtest.h>

#include "cli_image.h"
#include "cli_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::read_pixels;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::slurp;


fs::path temp_dir() {
    const fs::path dir = fs::temp_directory_path() / ("whitted_skip_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}


bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const std::string kScene = std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json";

TEST(SkipCli, NoSpecializeSelectsTheGeneralKernelWithTheSameImage) {
    const fs::path general = temp_dir() / "general.exr", special = temp_dir() / "special.exr";
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
    const fs::path out = temp_dir() / "log.png";
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
}

}  // namespace
