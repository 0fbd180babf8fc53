// `mpirun -n N whitted render`: the image of every rank count is the single process's, bit for
// bit; a bad scene fails once with a non-zero exit; a rank that dies ends the job, naming it
// (docs/distributed.md). The ranks run oversubscribed on the test machine, as root where CI is.
#include <gtest/gtest.h>

#include "tests/support/cli_image.h"
#include "tests/support/cli_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using whitted::test::contains;
using whitted::test::read_pixels;
using whitted::test::Result;
using whitted::test::run;
using whitted::test::scratch_dir;
using whitted::test::slurp;

const std::string kRoom = std::string(WHITTED_ASSETS_DIR) + "/scenes/glass_mirror_room.json";

std::string q(const fs::path& p) { return whitted::test::quoted(p); }

/// The mpirun line verified on this machine kind (../shared/STACK.md): as root, no ssh, ranks not
/// pinned, the ob1 transport.
std::string mpirun(int ranks) {
    return std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated "
                       "OMPI_MCA_btl_vader_single_copy_mechanism=none '") +
           WHITTED_MPIEXEC + "' --oversubscribe --bind-to none --mca pml ob1 -n " +
           std::to_string(ranks) + " '" + WHITTED_EXE + "' ";
}

Result shell(const std::string& cmd, const fs::path& dir) {
    const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const int status = std::system((cmd + " >" + q(out) + " 2>" + q(err) + " </dev/null").c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

// 1, 2, 3 and 4 ranks, one or two threads each, other tile sizes and anti-aliasing modes, every
// AOV: the single process's image.
TEST(Mpi, EveryRankCountGivesTheSingleProcessImage) {
    const fs::path dir = scratch_dir("whitted_mpi", "same");
    struct Case {
        std::string flags;
        std::vector<int> ranks;
    };
    const Case cases[] = {{"--aa adaptive --threads 1", {1, 2, 3, 4}},
                          {"--aa stratified --spp 4 --threads 2 --tile-size 13", {2, 3}},
                          {"--aa corners --threads 1 --tile-size 200", {2}},
                          {"--aa adaptive --threads 1 --tile-order cost", {3}}};
    for (const Case& c : cases) {
        const std::string common = "render " + q(kRoom) + " --width 160 --aov all --exr-float --no-progress " + c.flags;
        const Result one = run(common + " -o " + q(dir / "one.exr"));
        ASSERT_EQ(one.code, 0) << one.err;
        const std::vector<float> want = read_pixels(dir / "one.exr");
        ASSERT_FALSE(want.empty());
        for (const int n : c.ranks) {
            SCOPED_TRACE(c.flags + ", " + std::to_string(n) + " ranks");
            std::string name = "mpi";
            name += std::to_string(n);
            name += ".exr";
            const fs::path out = dir / name;
            fs::remove(out);
            const Result r = shell(mpirun(n) + common + " -o " + q(out), dir);
            ASSERT_EQ(r.code, 0) << r.err;
            if (n > 1) {
                std::string line = "MPI: ";
                line += std::to_string(n);
                line += " ranks";
                EXPECT_TRUE(contains(r.err, line)) << r.err;
            }
            EXPECT_EQ(read_pixels(out), want);
        }
    }
}

// A scene that cannot be loaded fails on every rank: one error line, a non-zero exit of the job.
TEST(Mpi, BadSceneFailsOnceWithNonZeroExit) {
    const fs::path dir = scratch_dir("whitted_mpi", "bad");
    const Result r = shell(mpirun(3) + "render " + q(dir / "missing.glb") + " -o " + q(dir / "x.exr"), dir);
    EXPECT_NE(r.code, 0);
    size_t lines = 0;
    for (size_t at = r.err.find("whitted: error:"); at != std::string::npos; at = r.err.find("whitted: error:", at + 1))
        ++lines;
    EXPECT_EQ(lines, 1u) << r.err;
    EXPECT_TRUE(contains(r.err, "missing.glb")) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.exr"));
}

/// The pids of the job's whitted processes with OMPI_COMM_WORLD_RANK == rank.
std::vector<pid_t> rank_pids(const std::string& output_name, int rank) {
    std::vector<pid_t> pids;
    for (const auto& entry : fs::directory_iterator("/proc")) {
        const std::string name = entry.path().filename().string();
        if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
        const std::string cmdline = slurp(entry.path() / "cmdline");
        if (!contains(cmdline, output_name) || contains(cmdline, "mpirun")) continue;
        std::string env = slurp(entry.path() / "environ");
        std::replace(env.begin(), env.end(), '\0', '\n');
        std::string key = "\nOMPI_COMM_WORLD_RANK=";
        key += std::to_string(rank);
        key += '\n';
        if (contains(env, key)) pids.push_back(pid_t(std::stoi(name)));
    }
    return pids;
}

// A rank killed mid-render ends the job within seconds with an error naming the rank: no hang.
TEST(Mpi, DeadRankEndsTheJobNamingIt) {
    const fs::path dir = scratch_dir("whitted_mpi", "dead");
    std::string out_name = "dead_rank_";
    out_name += std::to_string(::getpid());
    out_name += ".exr";
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = mpirun(3) + "render " + q(kRoom) + " --width 640 --aa stratified --spp 64 --threads 1 " +
                            "--no-progress -o " + q(dir / out_name) + " 2>" + q(err) + " </dev/null >/dev/null";
    const pid_t job = ::fork();
    if (job == 0) {
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    std::vector<pid_t> victim;
    for (int i = 0; i < 400 && (victim.empty() || !contains(slurp(err), "MPI:")); ++i) {
        ::usleep(50 * 1000);
        victim = rank_pids(out_name, 1);
    }
    ASSERT_EQ(victim.size(), 1u) << slurp(err);
    ::usleep(500 * 1000);
    ASSERT_EQ(::kill(victim.front(), SIGKILL), 0);
    int status = 0, code = -1;
    for (int i = 0; i < 300; ++i) {  // 15 s
        if (::waitpid(job, &status, WNOHANG) == job) {
            code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
            break;
        }
        ::usleep(50 * 1000);
    }
    if (code == -1) {
        ::kill(job, SIGKILL);
        ::waitpid(job, &status, 0);
        for (int r = 0; r < 3; ++r)
            for (pid_t p : rank_pids(out_name, r)) ::kill(p, SIGKILL);
        FAIL() << "the job did not end within 15 s of a rank's death: " << slurp(err);
    }
    EXPECT_NE(code, 0);
    EXPECT_TRUE(contains(slurp(err), "rank 1")) << slurp(err);
}

// Under mpirun, SIGUSR1 to mpirun (which passes it on and keeps the job) stops a distributed
// render gracefully: rank 0 writes the finished tiles and the checkpoint; `--resume` under mpirun
// finishes the single process's image.
TEST(Mpi, Sigusr1StopsGracefullyAndResumeFinishesTheImage) {
    const fs::path dir = scratch_dir("whitted_mpi", "usr1");
    const std::string flags = " --width 640 --aa stratified --spp 16 --threads 1 --exr-float --no-progress -o ";
    const fs::path out = dir / "out.exr", err = dir / "stderr.txt";
    const Result one = run("render " + q(kRoom) + flags + q(dir / "one.exr"));
    ASSERT_EQ(one.code, 0) << one.err;
    const pid_t job = ::fork();
    if (job == 0) {
        // exec: the pid is mpirun's, which passes SIGUSR1 on to the ranks.
        const std::string cmd = "exec env " + mpirun(2) + "render " + q(kRoom) + flags + q(out) + " 2>" + q(err) + " </dev/null";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    for (int i = 0; i < 400 && !contains(slurp(err), "MPI:"); ++i) ::usleep(50 * 1000);
    ::usleep(1000 * 1000);
    ASSERT_EQ(::kill(job, SIGUSR1), 0);
    const int code = whitted::test::wait_exit(job, 20.0);
    if (code == 0) GTEST_SKIP() << "the render finished before the signal";
    EXPECT_NE(code, -1) << "the job did not end: " << slurp(err);
    EXPECT_TRUE(contains(slurp(err), "continue with --resume")) << slurp(err);
    ASSERT_TRUE(fs::exists(dir / "out.exr.checkpoint.exr")) << slurp(err);
    const Result resumed = shell(mpirun(2) + "render " + q(kRoom) + flags + q(out) + " --resume", dir);
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    EXPECT_TRUE(contains(resumed.err, "resumed")) << resumed.err;
    EXPECT_EQ(read_pixels(out), read_pixels(dir / "one.exr"));
}

}  // namespace
