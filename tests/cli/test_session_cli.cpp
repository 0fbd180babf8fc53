// Interruption, checkpoints and resume, tile jobs and `whitted merge`, through the command line
// (docs/distributed.md): every way of finishing a frame in pieces gives the one-piece image.
#include <gtest/gtest.h>

#include "tests/support/cli_image.h"
#include "tests/support/cli_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace {

namespace fs = std::filesystem;
using whitted::test::contains;
using whitted::test::read_pixels;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::scratch_dir;
using whitted::test::slurp;
using whitted::test::wait_exit;

const std::string kRoom = std::string(WHITTED_ASSETS_DIR) + "/scenes/glass_mirror_room.json";
const std::string kBox = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";
/// Long enough to interrupt (about 3-10 s on two cores), with every AOV.
const std::string kSlow = "--width 640 --aa stratified --spp 16 --aov all --exr-float --no-progress";

std::string q(const fs::path& p) { return whitted::test::quoted(p); }

/// A string attribute of an image's header ("" when absent).
std::string attribute(const fs::path& path, const std::string& name) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return "";
    return in->spec().get_string_attribute(name);
}

/// Starts `whitted <args>` with stderr to `err`; returns its pid.
pid_t start(const std::string& args, const fs::path& err) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        const std::string cmd = std::string("exec '") + WHITTED_EXE + "' " + args + " 2>" + q(err) + " </dev/null";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    return pid;
}

/// Waits (up to 20 s) until the render has started: the log line naming the camera.
void wait_for_render(const fs::path& err) {
    for (int i = 0; i < 400 && !contains(slurp(err), "camera"); ++i) ::usleep(50 * 1000);
}

/// The uninterrupted image, once per test program.
const std::vector<float>& reference() {
    static const std::vector<float> px = [] {
        const fs::path dir = scratch_dir("whitted_session", "reference");
        const Result r = run("render " + q(kRoom) + " " + kSlow + " -o " + q(dir / "ref.exr"));
        EXPECT_EQ(r.code, 0) << r.err;
        return read_pixels(dir / "ref.exr");
    }();
    return px;
}

// SIGINT or SIGTERM at several moments of a render: the process stops within seconds, writes the
// finished tiles (the missing ones listed in the image's metadata) and a checkpoint; --resume
// renders the rest, and the result is the uninterrupted image bit for bit (every AOV).
TEST(Session, InterruptThenResumeGivesTheUninterruptedImage) {
    ASSERT_FALSE(reference().empty());
    int k = 0;
    for (const auto& [sig, delay_ms] : {std::pair{SIGINT, 300}, std::pair{SIGTERM, 900}, std::pair{SIGINT, 1800}}) {
        SCOPED_TRACE("signal " + std::to_string(sig) + " after " + std::to_string(delay_ms) + " ms");
        const fs::path dir = scratch_dir("whitted_session", "interrupt" + std::to_string(k++));
        const fs::path out = dir / "out.exr", err = dir / "err.txt";
        const pid_t pid = start("render " + q(kRoom) + " " + kSlow + " -o " + q(out), err);
        wait_for_render(err);
        ::usleep(useconds_t(delay_ms) * 1000);
        ::kill(pid, sig);
        const int code = wait_exit(pid, 15.0);
        if (code == 0) {  // finished before the signal arrived (a very fast machine): nothing to resume
            EXPECT_EQ(read_pixels(out), reference());
            continue;
        }
        ASSERT_EQ(code, 128 + sig) << slurp(err);
        EXPECT_TRUE(contains(slurp(err), "continue with --resume")) << slurp(err);
        ASSERT_TRUE(fs::exists(out));
        EXPECT_FALSE(attribute(out, "whitted:missingTiles").empty());
        EXPECT_TRUE(contains(attribute(out, "whitted:incomplete"), "tiles missing"));
        ASSERT_TRUE(fs::exists(dir / "out.exr.checkpoint.exr"));
        EXPECT_NE(read_pixels(out), reference());  // partial: the missing tiles are 0

        const Result resumed = run("render " + q(kRoom) + " " + kSlow + " -o " + q(out) + " --resume");
        ASSERT_EQ(resumed.code, 0) << resumed.err;
        EXPECT_TRUE(contains(resumed.err, "resumed")) << resumed.err;
        EXPECT_EQ(read_pixels(out), reference());
        EXPECT_FALSE(fs::exists(dir / "out.exr.checkpoint.exr")) << "a finished frame removes its checkpoint";
        EXPECT_TRUE(attribute(out, "whitted:missingTiles").empty());
    }
}

// --checkpoint saves periodically: a render killed outright (SIGKILL, no handler runs) leaves a
// whole checkpoint, from which --resume finishes the uninterrupted image.
TEST(Session, PeriodicCheckpointSurvivesAKill) {
    ASSERT_FALSE(reference().empty());
    const fs::path dir = scratch_dir("whitted_session", "periodic");
    const fs::path out = dir / "out.exr", err = dir / "err.txt", ckpt = dir / "out.exr.checkpoint.exr";
    const pid_t pid = start("render " + q(kRoom) + " " + kSlow + " --checkpoint 0.2 -o " + q(out), err);
    wait_for_render(err);
    for (int i = 0; i < 200 && !fs::exists(ckpt); ++i) ::usleep(50 * 1000);
    ::usleep(500 * 1000);
    ::kill(pid, SIGKILL);
    const int code = wait_exit(pid, 10.0);
    if (code == 0) GTEST_SKIP() << "the render finished before the kill";
    // The checkpoint is whole (a kill during its write leaves the previous one and a temporary file
    // that is never read); the output was never written.
    ASSERT_TRUE(fs::exists(ckpt)) << slurp(err);
    EXPECT_FALSE(read_pixels(ckpt).empty());
    EXPECT_FALSE(fs::exists(out));
    const Result resumed = run("render " + q(kRoom) + " " + kSlow + " -o " + q(out) + " --resume");
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    EXPECT_EQ(read_pixels(out), reference());
}

// A checkpoint made with other settings is refused in one line naming the setting; without one,
// --resume says so.
TEST(Session, ResumeRefusesOtherSettings) {
    const fs::path dir = scratch_dir("whitted_session", "refuse");
    const fs::path out = dir / "out.exr";
    Result none = run("render " + q(kBox) + " --width 64 --no-progress --resume -o " + q(out));
    EXPECT_EQ(none.code, 1);
    EXPECT_TRUE(contains(none.err, "no checkpoint")) << none.err;

    // An interrupted render's checkpoint, resumed with other settings.
    const fs::path err = dir / "err.txt";
    const pid_t pid = start("render " + q(kRoom) + " " + kSlow + " -o " + q(out), err);
    wait_for_render(err);
    ::usleep(300 * 1000);
    ::kill(pid, SIGINT);
    const int code = wait_exit(pid, 15.0);
    if (code == 0) GTEST_SKIP() << "the render finished before the signal";
    ASSERT_EQ(code, 128 + SIGINT);
    Result other = run("render " + q(kRoom) + " " + kSlow + " --max-depth 2 --resume -o " + q(out));
    EXPECT_EQ(other.code, 1);
    EXPECT_TRUE(contains(other.err, "made with max_depth = 8, this render has max_depth = 2")) << other.err;
    std::string narrower = kSlow;
    narrower.replace(narrower.find("--width 640"), 11, "--width 600");
    Result wider = run("render " + q(kRoom) + " " + narrower + " --resume -o " + q(out));
    EXPECT_EQ(wider.code, 1);
    EXPECT_TRUE(contains(wider.err, "width = 640, this render has width = 600")) << wider.err;
}

// n tile jobs merged in any order give the one-piece frame: EXR bit for bit (every AOV), PNG
// through the same OCIO path; also a tile job of a crop.
TEST(Session, TileJobsMergeToTheOnePieceFrame) {
    const fs::path dir = scratch_dir("whitted_session", "jobs");
    for (const std::string aa : {"adaptive", "corners", "stratified --spp 4"}) {
        SCOPED_TRACE(aa);
        const std::string common = "render " + q(kRoom) + " --width 160 --aov all --no-progress --aa " + aa;
        ASSERT_EQ(run(common + " --exr-float -o " + q(dir / "one.exr")).code, 0);
        ASSERT_EQ(run(common + " -o " + q(dir / "one.png")).code, 0);
        std::string parts;
        for (int i = 3; i >= 1; --i) {
            const fs::path part = dir / ("part" + std::to_string(i) + ".exr");
            const Result r = run(common + " --tile-job " + std::to_string(i) + "/3 -o " + q(part));
            ASSERT_EQ(r.code, 0) << r.err;
            EXPECT_EQ(attribute(part, "whitted:tileJob"), std::to_string(i) + "/3");
            parts += ' ';
            parts += q(part);
        }
        Result m = run("merge" + parts + " --exr-float -o " + q(dir / "merged.exr"));
        ASSERT_EQ(m.code, 0) << m.err;
        EXPECT_EQ(read_pixels(dir / "merged.exr"), read_pixels(dir / "one.exr"));
        m = run("merge" + parts + " -o " + q(dir / "merged.png"));
        ASSERT_EQ(m.code, 0) << m.err;
        EXPECT_EQ(read_pixels(dir / "merged.png"), read_pixels(dir / "one.png"));
    }
    // A crop in 2 jobs.
    const std::string crop = "render " + q(kRoom) + " --width 160 --crop 20,10,140,90 --no-progress";
    ASSERT_EQ(run(crop + " --exr-float -o " + q(dir / "crop.exr")).code, 0);
    ASSERT_EQ(run(crop + " --tile-job 1/2 -o " + q(dir / "c1.exr")).code, 0);
    ASSERT_EQ(run(crop + " --tile-job 2/2 -o " + q(dir / "c2.exr")).code, 0);
    ASSERT_EQ(run("merge " + q(dir / "c2.exr") + " " + q(dir / "c1.exr") + " --exr-float -o " + q(dir / "cm.exr")).code, 0);
    EXPECT_EQ(read_pixels(dir / "cm.exr"), read_pixels(dir / "crop.exr"));
}

/// How an EXR stores its beauty's R channel: "float" or "half".
std::string beauty_format(const fs::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return "unreadable";
    const OIIO::ImageSpec& spec = in->spec();
    const int r = spec.channelindex("R");
    return r < 0 ? "no R" : std::string(spec.channelformat(r).c_str());
}

// `whitted merge` is lossless by default: float parts (what --tile-job writes) give a float EXR
// equal to the one-piece float render; --exr-half asks for half, and with --exr-float it is refused.
TEST(Session, MergeKeepsThePartsPrecision) {
    const fs::path dir = scratch_dir("whitted_session", "merge_precision");
    const std::string render = "render " + q(kRoom) + " --width 96 --no-progress";
    ASSERT_EQ(run(render + " --exr-float -o " + q(dir / "one.exr")).code, 0);
    ASSERT_EQ(run(render + " --tile-job 1/2 -o " + q(dir / "p1.exr")).code, 0);
    ASSERT_EQ(run(render + " --tile-job 2/2 -o " + q(dir / "p2.exr")).code, 0);
    EXPECT_EQ(beauty_format(dir / "p1.exr"), "float");
    const std::string parts = " " + q(dir / "p1.exr") + " " + q(dir / "p2.exr");
    Result m = run("merge" + parts + " -o " + q(dir / "merged.exr"));
    ASSERT_EQ(m.code, 0) << m.err;
    EXPECT_EQ(beauty_format(dir / "merged.exr"), "float");
    EXPECT_EQ(read_pixels(dir / "merged.exr"), read_pixels(dir / "one.exr"));
    m = run("merge" + parts + " --exr-half -o " + q(dir / "half.exr"));
    ASSERT_EQ(m.code, 0) << m.err;
    EXPECT_EQ(beauty_format(dir / "half.exr"), "half");
    EXPECT_NE(read_pixels(dir / "half.exr"), read_pixels(dir / "one.exr"));  // rounded to half
    m = run("merge" + parts + " --exr-half --exr-float -o " + q(dir / "both.exr"));
    EXPECT_EQ(m.code, 2) << m.err;
    EXPECT_FALSE(fs::exists(dir / "both.exr"));
}

// --tile-log: a row per tile with its time and message size, for scripts/simulate_mpi.py.
TEST(Session, TileLogHasARowPerTile) {
    const fs::path dir = scratch_dir("whitted_session", "tilelog");
    const Result r = run("render " + q(kRoom) + " --width 100 --tile-size 16 --no-progress -o " + q(dir / "x.png") +
                         " --tile-log " + q(dir / "tiles.csv"));
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = whitted::test::read_csv(dir / "tiles.csv");
    ASSERT_EQ(rows.size(), 7u * 5u);  // 100 x 67 in tiles of 16
    double sum = 0;
    for (const auto& row : rows) {
        EXPECT_GT(whitted::test::num(row, "seconds"), 0.0);
        const double w = whitted::test::num(row, "x1") - whitted::test::num(row, "x0");
        const double h = whitted::test::num(row, "y1") - whitted::test::num(row, "y0");
        EXPECT_EQ(whitted::test::num(row, "bytes"), 4 + 12 * w * h);
        sum += w * h;
    }
    EXPECT_EQ(sum, 100.0 * 67.0);
}

// Parts that do not make one frame: one clear line naming the part, exit 1.
TEST(Session, MergeNamesTheMissingOverlappingOrForeignPart) {
    const fs::path dir = scratch_dir("whitted_session", "badjobs");
    const std::string common = "render " + q(kRoom) + " --width 96 --no-progress";
    for (int i = 1; i <= 3; ++i)
        ASSERT_EQ(run(common + " --tile-job " + std::to_string(i) + "/3 -o " + q(dir / ("p" + std::to_string(i) + ".exr"))).code, 0);
    ASSERT_EQ(run(common + " --max-depth 2 --tile-job 2/3 -o " + q(dir / "other.exr")).code, 0);
    ASSERT_EQ(run(common + " --tile-job 2/4 -o " + q(dir / "four.exr")).code, 0);
    ASSERT_EQ(run(common + " -o " + q(dir / "plain.exr")).code, 0);
    const std::string p1 = q(dir / "p1.exr"), p2 = q(dir / "p2.exr"), p3 = q(dir / "p3.exr");
    const struct {
        std::string parts, message;
    } cases[] = {
        {p1 + " " + p3, "part 2/3 (rows 22-42) is missing"},
        {p1 + " " + p2 + " " + p2 + " " + p3, "are both part 2/3: they overlap"},
        {p1 + " " + q(dir / "other.exr") + " " + p3, "made with max_depth = 2, but"},
        {p1 + " " + q(dir / "four.exr") + " " + p3, "of another job"},
        {p1 + " " + q(dir / "plain.exr"), "not a tile-job part"},
        {p1 + " " + q(dir / "nothing.exr"), "nothing.exr"},
    };
    for (const auto& c : cases) {
        const Result r = run("merge " + c.parts + " -o " + q(dir / "out.exr"));
        EXPECT_EQ(r.code, 1) << c.message;
        EXPECT_TRUE(contains(r.err, c.message)) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    for (const std::string bad : {"0/3", "4/3", "x", "1/0", "2/3/4"}) {
        const Result r = run(common + " --tile-job " + bad + " -o " + q(dir / "bad.exr"));
        EXPECT_EQ(r.code, 1) << bad;
        EXPECT_TRUE(contains(r.err, "--tile-job")) << r.err;
    }
    const Result png = run(common + " --tile-job 1/3 -o " + q(dir / "part.png"));
    EXPECT_EQ(png.code, 1);
    EXPECT_TRUE(contains(png.err, "EXR part")) << png.err;
}

}  // namespace
