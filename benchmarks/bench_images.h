// What the benchmarks compare images by: packed linear RGB, the display values a PNG stores
// (the OCIO transform `whitted render` writes with, clamped to [0, 1]), RMSE between two, and
// running a plot script on a CSV when python3 with matplotlib is there.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/log.h"
#include "film/film.h"
#include "output/image_output.h"

namespace whitted::app {

/// The film's beauty as packed RGB floats (linear).
inline std::vector<float> packed_rgb(const Film& film) {
    std::vector<float> rgb(film.beauty.size() * 3);
    for (size_t i = 0; i < film.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = film.beauty[i][c];
    return rgb;
}

/// Display-referred values of packed linear RGB: `display` applied, NaN -> 0, clamped to [0, 1]
/// (1/255 is one 8-bit code of a PNG).
inline std::vector<float> display_rgb(std::vector<float> rgb, const DisplayTransform& display) {
    display.apply(rgb.data(), rgb.size() / 3);
    for (float& v : rgb) v = std::isnan(v) ? 0.f : std::clamp(v, 0.f, 1.f);
    return rgb;
}

/// Root-mean-square difference of two equally long value arrays (0 for empty ones).
inline double rmse(const std::vector<float>& a, const std::vector<float>& b) {
    double se = 0.0;
    for (size_t i = 0; i < a.size(); ++i) se += (double(a[i]) - double(b[i])) * (double(a[i]) - double(b[i]));
    return a.empty() ? 0.0 : std::sqrt(se / double(a.size()));
}

/// Largest absolute difference of two equally long value arrays.
inline double max_abs_difference(const std::vector<float>& a, const std::vector<float>& b) {
    double m = 0.0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(double(a[i]) - double(b[i])));
    return m;
}

/// Debian's interpreter, where the packages the set-up installs (python3-matplotlib) live, before
/// whatever `python3` the PATH finds first (a pyenv or venv one may lack them).
inline std::string default_python() {
    return std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
}

/// Runs `python scripts/<script> CSV OUT_DIR` when the interpreter has matplotlib; otherwise (or
/// when the script fails) logs one warning with the command to run later. `bench` names the
/// caller in the warning.
inline void run_plot_script(const std::string& python, const std::string& script, const std::filesystem::path& csv,
                            const std::filesystem::path& out_dir, const std::string& bench) {
    const std::filesystem::path path = std::filesystem::path(WHITTED_SOURCE_DIR) / "scripts" / script;
    const std::string cmd = fmt::format("{} '{}' '{}' '{}'", python, path.string(), csv.string(), out_dir.string());
    if (std::filesystem::exists(path) && std::system((python + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
        if (std::system(cmd.c_str()) != 0) log_warning("{}: plotting failed: {}", bench, cmd);
    } else {
        log_warning("{}: python3 with matplotlib not found; plot later with: {}", bench, cmd);
    }
}

}  // namespace whitted::app
