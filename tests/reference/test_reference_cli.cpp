// The `whitted-reference` program end to end: the same scene file rendered by `whitted render`
// with the reference's sampling (one ray per pixel centre, --min-weight 0, --texture-filter none,
// float EXR) and by `whitted-reference` agree to the bounds of test_reference_compare; bad input
// gets one error line naming the problem and a non-zero exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tests/support/cli_image.h"
#include "tests/support/cli_util.h"

namespace whitted {
namespace {

using namespace whitted::test;

/// Runs whitted-reference with `args` (shell-quoted by the caller).
Result run_reference(const std::string& args) { return run_program(WHITTED_REFERENCE_EXE, args); }

TEST(ReferenceCli, AgreesWithWhittedRenderOnTheDefaultScene) {
    const std::filesystem::path dir = scratch_dir("whitted_reference_cli", "default");
    const std::string scene = quoted(std::filesystem::path(WHITTED_ASSETS_DIR) / "scenes/whitted1980.json");
    const std::filesystem::path prod = dir / "prod.exr", ref = dir / "ref.exr";
    const Result p = run("render " + scene + " -o " + quoted(prod) +
                         " --width 64 --aa center --min-weight 0 --texture-filter none --exr-float --no-progress");
    ASSERT_EQ(p.code, 0) << p.err;
    const Result r = run_reference(scene + " -o " + quoted(ref) + " --width 64");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<float> a = read_pixels(prod), b = read_pixels(ref);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GE(a.size(), size_t(64 * 48 * 3));
    double sum_sq = 0.0, peak = 1.0;
    size_t beyond = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const double d = double(a[i]) - double(b[i]);
        sum_sq += d * d;
        peak = std::max(peak, double(b[i]));
        beyond += std::fabs(d) > 1e-3 * std::max({std::fabs(double(a[i])), std::fabs(double(b[i])), 1e-3});
    }
    const double psnr = 10.0 * std::log10(peak * peak / std::max(sum_sq / double(a.size()), 1e-300));
    EXPECT_GE(psnr, 60.0);
    EXPECT_EQ(beyond, 0u);  // no channel differs by more than 1e-3 relative (test_reference_compare: < 2e-4)
    // The comparison can fail: the reference with another ambient light is caught.
    const Result r2 = run_reference(scene + " -o " + quoted(ref) + " --width 64 --ambient 0.2");
    ASSERT_EQ(r2.code, 0) << r2.err;
    const std::vector<float> c = read_pixels(ref);
    ASSERT_EQ(c.size(), a.size());
    size_t moved = 0;
    for (size_t i = 0; i < a.size(); ++i) moved += std::fabs(double(a[i]) - double(c[i])) > 1e-3;
    EXPECT_GT(moved, a.size() / 2);
}

TEST(ReferenceCli, BadInputIsOneErrorLine) {
    const std::filesystem::path dir = scratch_dir("whitted_reference_cli", "bad");
    const std::string scene = quoted(std::filesystem::path(WHITTED_ASSETS_DIR) / "scenes/whitted1980.json");
    struct Case {
        std::string args, expect;
    };
    const std::vector<Case> cases = {
        {quoted(dir / "missing.json") + " -o " + quoted(dir / "x.exr"), "missing.json"},
        {scene + " -o " + quoted(dir / "x.png"), ".exr"},
        {scene + " -o " + quoted(dir / "x.exr") + " --aa adaptive", "anti-aliasing"},
        {scene + " -o " + quoted(dir / "x.exr") + " --min-weight 0.01", "min-weight"},
        {scene + " -o " + quoted(dir / "x.exr") + " --texture-filter mip", "texture-filter"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const Result r = run_reference(c.args);
        EXPECT_NE(r.code, 0);
        EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
}

}  // namespace
}  // namespace whitted
