// The fixed cost of a run (docs/performance.md "Fixed cost of a run"): OpenImageIO, with its ~260
// shared libraries, is loaded only by runs that read an image file other than EXR through it (an
// environment or scene-file texture in PNG, HDR, ...); --help, info, and renders to PNG, EXR, JPEG
// or TIFF with the bundled environment never do. Checked
// through glibc's loader log (LD_DEBUG=files), which names every library a process maps.
#include <gtest/gtest.h>

#include "tests/support/cli_util.h"

#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using whitted::test::contains;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::slurp;

const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";

/// Runs whitted with the loader's log on and returns every library the processes mapped.
std::string libraries_loaded_by(const std::string& args, Result* result = nullptr) {
    const fs::path dir = whitted::test::scratch_dir("whitted_startup_cli", "ld");
    const fs::path log = dir / "ld";
    ::setenv("LD_DEBUG", "files", 1);
    ::setenv("LD_DEBUG_OUTPUT", log.c_str(), 1);
    const Result r = run(args);
    ::unsetenv("LD_DEBUG");
    ::unsetenv("LD_DEBUG_OUTPUT");
    if (result) *result = r;
    std::string all;
    for (const auto& entry : fs::directory_iterator(dir)) all += slurp(entry.path());
    fs::remove_all(dir);
    return all;
}

TEST(StartupCli, HelpAndInfoDoNotLoadOpenImageIO) {
    Result r;
    std::string libs = libraries_loaded_by("--help", &r);
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(contains(libs, "libembree3")) << "the loader log is empty?\n" << libs.substr(0, 2000);
    EXPECT_FALSE(contains(libs, "libOpenImageIO")) << "--help loaded OpenImageIO";
    libs = libraries_loaded_by("info '" + kBox + "'", &r);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(contains(libs, "libOpenImageIO")) << "info loaded OpenImageIO";
}

TEST(StartupCli, RendersToEveryFormatDoNotLoadOpenImageIOReadingAPngDoes) {
    const fs::path dir = whitted::test::scratch_dir("whitted_startup_cli", "render");
    Result r;
    for (const char* ext : {"png", "exr", "jpg", "tif"}) {
        const fs::path out = dir / (std::string("box.") + ext);
        const std::string libs =
            libraries_loaded_by("render '" + kBox + "' --width 64 --no-progress -o '" + out.string() + "'", &r);
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_TRUE(fs::exists(out)) << out;
        EXPECT_FALSE(contains(libs, "libOpenImageIO")) << "a render to ." << ext << " loaded OpenImageIO";
    }
    // A PNG environment is read through the module.
    const std::string libs = libraries_loaded_by("render '" + kBox + "' --width 16 --no-progress --environment '" +
                                                     (dir / "box.png").string() + "' -o '" + (dir / "env.exr").string() + "'",
                                                 &r);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(libs, "libwhitted_oiio.so")) << "a PNG environment did not load the image module";
    EXPECT_TRUE(contains(libs, "libOpenImageIO"));
    fs::remove_all(dir);
}

// Runs that load or render restart once with glibc's malloc asking for transparent huge pages
// (src/core/huge_pages.h) when the kernel offers them, except runs whose only files are small
// scene files; WHITTED_HUGE_PAGES=0 and a caller's own GLIBC_TUNABLES setting are respected.
TEST(StartupCli, RunsAskForHugePagesWhenTheKernelOffersThem) {
    const std::string thp = slurp("/sys/kernel/mm/transparent_hugepage/enabled");
    const bool offered = contains(thp, "[always]") || contains(thp, "[madvise]");
    const std::string box = "info '" + kBox + "' --log-level debug";
    Result r = run(box);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, offered ? "transparent huge pages requested" : "transparent huge pages not requested"))
        << "kernel: " << thp << "\n" << r.err;
    r = run("info '" + std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json' --log-level debug");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "transparent huge pages not requested")) << "a small scene file restarted\n" << r.err;
    ::setenv("WHITTED_HUGE_PAGES", "0", 1);
    r = run(box);
    ::unsetenv("WHITTED_HUGE_PAGES");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "transparent huge pages not requested")) << r.err;
    ::setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=0", 1);
    r = run(box);
    ::unsetenv("GLIBC_TUNABLES");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "transparent huge pages not requested")) << r.err;
}

// $WHITTED_IMAGE_MODULE names the module to use, with no fallback: a missing one is one clear
// error line naming it and a non-zero exit, never a crash, and no file is left behind.
TEST(StartupCli, MissingImageModuleIsOneClearError) {
    const fs::path dir = whitted::test::scratch_dir("whitted_startup_cli", "missing");
    ASSERT_EQ(run("render '" + kBox + "' --width 16 --no-progress -o '" + (dir / "env.png").string() + "'").code, 0);
    ::setenv("WHITTED_IMAGE_MODULE", (dir / "nowhere.so").c_str(), 1);
    const Result r = run("render '" + kBox + "' --width 16 --no-progress --environment '" + (dir / "env.png").string() +
                         "' -o '" + (dir / "box.exr").string() + "'");
    ::unsetenv("WHITTED_IMAGE_MODULE");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(contains(r.err, "libwhitted_oiio.so")) << r.err;
    EXPECT_TRUE(contains(r.err, "nowhere.so")) << r.err;
    EXPECT_FALSE(fs::exists(dir / "box.exr"));
    size_t error_lines = 0;
    for (size_t at = r.err.find("error"); at != std::string::npos; at = r.err.find("error", at + 1)) ++error_lines;
    EXPECT_EQ(error_lines, 1u) << r.err;
    fs::remove_all(dir);
}

}  // namespace
