// `whitted bench process --vs-povray` end to end with POV-Ray (Debian's povray, which the set-up
// installs) at tiny sizes: every setting of both programs timed and scored, the two programs'
// converged images of each exported scene alike (the exporters wrote the same scene), the ratio
// lines printed; a POV-Ray that is not there is one clear error. No time is checked.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <cmath>
#include <filesystem>
#include <fstream>
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
    const Result r = run("bench process --vs-povray --pov-scenes whitted1980,rings,balls,tetra,mount,gears --spd-size 1 "
                         "--pov-scale 0.05 --repeat 1 --threads 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const std::vector<std::map<std::string, std::string>> rows = read_csv(out / "versus_povray.csv");
    constexpr size_t kScenes = 6;
    ASSERT_EQ(rows.size(), kScenes * (13u + 13u));  // whitted's 13 settings and POV-Ray's 13, per scene
    std::map<std::string, int> per_program;
    for (const auto& row : rows) {
        ++per_program[row.at("program")];
        EXPECT_GT(num(row, "wall_seconds"), 0.0);
        EXPECT_GT(num(row, "cpu_seconds"), 0.0);
        EXPECT_GT(num(row, "psnr_db"), 15.0) << row.at("scene") << " " << row.at("program") << " " << row.at("setting");
    }
    EXPECT_EQ(per_program["whitted"], int(kScenes) * 13);
    EXPECT_EQ(per_program["povray"], int(kScenes) * 13);
    // The converged images of both programs agree (a flipped camera, a shifted checker, a wrong
    // index of refraction or a missing light would not).
    const std::regex agree(R"(the references, whitted's against POV-Ray's: ([0-9.]+|inf) dB)");
    int scenes = 0;
    for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), agree); it != std::sregex_iterator(); ++it, ++scenes)
        EXPECT_GT(std::stod((*it)[1]), 36.0) << r.out;  // 41-48 dB measured
    EXPECT_EQ(scenes, int(kScenes)) << r.out;
    EXPECT_NE(r.out.find("at POV-Ray +AM1 +A0.3 +R3"), std::string::npos) << r.out;
    for (const char* name : {"rings", "balls", "tetra", "mount", "gears"})
        EXPECT_TRUE(fs::exists(out / "povray" / (std::string(name) + ".pov"))) << name;
    EXPECT_TRUE(fs::exists(out / "povray" / "whitted1980.json"));
}

// A scene file of its own: a transformed (rotated, non-uniformly scaled) capped cylinder, an open
// cone, an annulus, a rotated box mesh, a glass sphere on an infinite checker plane, a point and a
// directional light. Both exporters must write the same scene (before the plane's checker took the
// flat meshes' step, the references agreed at 10.5 dB).
TEST(BenchPovrayCli, SceneFilesAreExportedAlike) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_povray_cli", "file");
    const fs::path scene = out / "shapes.json";
    std::ofstream(scene) << R"({
  "version": 1,
  "render": {"width": 320, "height": 180, "max_depth": 4, "background": [0.1, 0.12, 0.2]},
  "ambient": 0.1,
  "camera": {"position": [0, 6, 5], "look_at": [0, 0.5, 0], "fov": 40},
  "textures": {"chk": {"type": "checker", "colors": [[0.8, 0.8, 0.8], [0.2, 0.2, 0.25]], "size": 1, "space": "world"}},
  "materials": {
    "floor": {"kd": "chk", "ka": "chk"},
    "red": {"kd": [0.8, 0.15, 0.1], "highlight": 0.5, "n": 40},
    "blue": {"kd": [0.1, 0.2, 0.8], "highlight": 0.4, "n": 20, "kr": 0.3},
    "gold": {"kd": [0.7, 0.55, 0.1], "highlight": 0.6, "n": 60},
    "glass": {"kd": 0, "ka": 0, "highlight": 0.5, "n": 100, "kr": 0.1, "kt": 0.85, "ior": 1.5}
  },
  "objects": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"},
    {"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1.5, 0], "radius": 0.4, "material": "red",
     "transform": {"translate": [-1.6, 0, 0], "rotate": [20, 0, 0, 1], "scale": [1.6, 1, 0.6]}},
    {"type": "cone", "base": [0, 0, 0], "apex": [0, 1.4, 0], "base_radius": 0.6, "apex_radius": 0.15, "open": true,
     "material": "blue", "transform": {"translate": [0.2, 0, -0.6]}},
    {"type": "disc", "center": [1.7, 0.9, 0.3], "normal": [-0.5, 0.3, 1], "radius": 0.6, "inner_radius": 0.25, "material": "gold"},
    {"type": "sphere", "center": [0.6, 0.5, 1.3], "radius": 0.5, "material": "glass"},
    {"type": "box", "min": [-0.3, 0, -0.3], "max": [0.3, 0.6, 0.3], "material": "gold",
     "transform": {"translate": [-0.4, 0, 1.6], "rotate": [30, 0, 1, 0]}}
  ],
  "lights": [
    {"type": "point", "position": [3, 6, 5], "intensity": 30},
    {"type": "directional", "direction": [-0.3, -1, -0.4], "intensity": 0.4}
  ]
})";
    const Result r = run("bench process --vs-povray --pov-scenes '" + scene.string() + "' --pov-scale 0.3 --repeat 1 "
                         "--threads 1 --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"(the references, whitted's against POV-Ray's: ([0-9.]+|inf) dB)")))
        << r.out;
    EXPECT_GT(std::stod(m[1]), 36.0) << r.out;
    EXPECT_NE(r.out.find("== shapes: 96x54"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(out / "povray" / "shapes.pov"));
}

TEST(BenchPovrayCli, SceneFileWithWhatPovrayCannotMatchIsOneError) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_povray_cli", "refused");
    const fs::path scene = out / "spot.json";
    std::ofstream(scene) << R"({
  "version": 1,
  "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40},
  "materials": {"m": {"kd": [0.8, 0.8, 0.8]}},
  "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
  "lights": [{"type": "spot", "position": [0, 4, 0], "direction": [0, -1, 0], "intensity": 10, "outer_angle": 30}]
})";
    const Result r = run("bench process --vs-povray --pov-scenes '" + scene.string() + "' --repeat 1 --out '" +
                         out.string() + "'");
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("spot"), std::string::npos) << r.err;
}

TEST(BenchPovrayCli, MissingPovrayIsOneClearError) {
    const fs::path out = whitted::test::scratch_dir("whitted_bench_povray_cli", "missing");
    const Result r = run("bench process --vs-povray --povray /nonexistent/povray --repeat 1 --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("POV-Ray not found ('/nonexistent/povray')"), std::string::npos) << r.err;
}

}  // namespace
