// `whitted bench process --vs-povray` end to end with POV-Ray (Debian's povray, which the set-up
// installs) at tiny sizes: every setting of both programs timed and scored, the two programs'
// converged images of each exported scene alike (the exporters wrote the same scene), the ratio
// lines printed; a POV-Ray that is not there is one clear error. No time is checked.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::num;
using whitted::test::read_csv;
using whitted::test::Result;
using whitted::test::run;

TEST(BenchPovrayCli, BothProgramsScoredOnTheSameScenes) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_povray_cli", "small");
    const Result r = run("bench process --vs-povray --pov-scenes whitted1980,rings --spd-size 1 --pov-scale 0.05 "
                         "--repeat 1 --threads 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<std::map<std::string, std::string>> rows = read_csv(out / "versus_povray.csv");
    ASSERT_EQ(rows.size(), 2u * (8u + 9u));  // whitted's 8 settings and POV-Ray's 9, per scene
    std::map<std::string, int> per_program;
    for (const auto& row : rows) {
        ++per_program[row.at("program")];
        EXPECT_GT(num(row, "wall_seconds"), 0.0);
        EXPECT_GT(num(row, "cpu_seconds"), 0.0);
        EXPECT_GT(num(row, "psnr_db"), 15.0) << row.at("scene") << " " << row.at("program") << " " << row.at("setting");
    }
    EXPECT_EQ(per_program["whitted"], 16);
    EXPECT_EQ(per_program["povray"], 18);
    // The converged images of both programs agree (a flipped camera, a shifted checker, a wrong
    // index of refraction or a missing light would not).
    const std::regex agree(R"(the references, whitted's against POV-Ray's: ([0-9.]+|inf) dB)");
    int scenes = 0;
    for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), agree); it != std::sregex_iterator(); ++it, ++scenes)
        EXPECT_GT(std::stod((*it)[1]), 36.0) << r.out;  // 41-48 dB measured
    EXPECT_EQ(scenes, 2) << r.out;
    EXPECT_NE(r.out.find("at POV-Ray +AM1 +A0.3 +R3"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(out / "povray" / "rings.pov"));
    EXPECT_TRUE(fs::exists(out / "povray" / "whitted1980.json"));
}

TEST(BenchPovrayCli, MissingPovrayIsOneClearError) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_povray_cli", "missing");
    const Result r = run("bench process --vs-povray --povray /nonexistent/povray --repeat 1 --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("POV-Ray not found ('/nonexistent/povray')"), std::string::npos) << r.err;
}

}  // namespace
