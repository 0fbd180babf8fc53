// `whitted bench process --vs-povray`: whitted against POV-Ray 3.7 at equal error, whole process
// (docs/performance.md, "Against POV-Ray at equal error").
//
// Each scene is written twice from the same Scene (scene_export.h): a whitted scene file and a
// POV-Ray scene. Each program renders its own converged reference (whitted: 8x8 stratified
// samples per pixel; POV-Ray: sampling method 1 with threshold 0, an 8x8 grid in every pixel),
// then a sweep of its anti-aliasing settings (whitted: centre, corners, adaptive thresholds and
// depths; POV-Ray: none, methods 1 and 2 at thresholds and depths), each run timed from spawn to
// exit (median of --repeat) and scored by PSNR of its 8-bit PNG against its own reference. At an
// error target E, a program's time is that of its fastest setting reaching E; the ratio is
// whitted's over POV-Ray's. The ratio is also given at the error of POV-Ray's usual setting
// (+A0.3, method 1, depth 3). Writes <out>/povray/<scene>.{json,pov} and versus_povray.csv.
#pragma once

#include <string>
#include <vector>

namespace whitted::app {

/// The scenes the comparison knows by name: whitted1980, then spd_scene_names().
std::vector<std::string> povray_scene_names();

struct VersusPovrayOptions {
    std::string whitted;                 ///< the whitted executable
    std::string povray = "povray";       ///< POV-Ray: a path, or a name looked up on the PATH
    /// whitted1980 (the bundled classic scene, 1920x1080), the SPD-style scenes (spd_scenes.h:
    /// rings, tree, balls, tetra, mount, gears; 512x512), or paths of classic scene files (at
    /// their render size, else 1920x1080)
    std::vector<std::string> scenes = povray_scene_names();
    int spd_size = 3;                    ///< SPD size factor of the SPD-style scenes
    double scale = 1.0;                  ///< image sizes scaled by this (tests use small images)
    int repeat = 3;
    int threads = 0;                     ///< both programs' threads (0: each its default, all cores)
    std::string out = "out/bench_process";
};

/// Runs the comparison and prints it; returns 0. Throws whitted::Error when POV-Ray is not found,
/// a scene cannot be exported or a run fails.
int run_versus_povray(const VersusPovrayOptions& options);

}  // namespace whitted::app
