// Issue 20's faults, with nothing lost: a run stopped by SIGINT or SIGTERM, or by a write error
// (a full disk, a file-size limit), keeps the complete records it wrote in "name.partial" (never
// under the output's name), says so, and the same command with -r finishes it with the matrix an
// uninterrupted run gives; a reader that closes the pipe ends the run as it ends RADIANCE's.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/outputs.h"
#include "rcontrib/run.h"
#include "test_util.h"
#include "util/signals.h"

namespace dayflux::test {
namespace {

namespace fs = std::filesystem;

const char *const kRoom = kFloorUnderSky;

// n sensors looking up at different heights (one input ray each), text.
std::string Rays(int n) {
    std::ostringstream s;
    for (int i = 0; i < n; ++i) s << "0 0 " << (i % 50) * 0.01 << " 0 0.3 1\n";
    return s.str();
}

const char *kArgs = "-seed 7 -ff -c 2 -ab 2 -ad 64 -lw 1e-4 -b 'if(Dz-.5,0,1)' -bn 2";

// In the process, so the signal comes at a known ray: it is raised by the ray source after 41
// rays; the blocks in flight finish, their 20 complete records (-c 2) are kept, and the rest is
// left to -r.
class SignalStop : public ::testing::TestWithParam<int> {};

TEST_P(SignalStop, KeepsTheRecordsAndRecoveryFinishesTheRun) {
    const int sig = GetParam();
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    std::vector<double> rays;
    {
        std::istringstream in(Rays(200));
        double v;
        while (in >> v) rays.push_back(v);
    }
    const auto run = [&](const std::string &out, bool recover, int raise_after) {
        std::vector<std::string> args = {
            "rcontrib-gpu", "-seed", "7",  "-ff",           "-c",  "2", "-ab", "1",
            "-ad",          "64",    "-b", "if(Dz-.5,0,1)", "-bn", "2"};
        if (recover) args.push_back("-r");
        for (const char *a : {"-o", "", "-m", "sky", ""}) args.emplace_back(a);
        args[args.size() - 4] = (tmp.path() / out).string();
        args.back() = (tmp.path() / "room.rad").string();
        std::vector<std::string> header;
        const RcontribOptions o = ParseRcontribOptions(args, &header);
        size_t next = 0;
        RunRcontrib(o, header, "", [&](double ray[6]) {
            if (next == rays.size()) return false;
            std::copy(&rays[next], &rays[next + 6], ray);
            next += 6;
            if (static_cast<int>(next / 6) == raise_after) std::raise(sig);
            return true;
        });
    };
    run("full.mtx", false, -1);
    try {
        run("cut.mtx", false, 41);
        ADD_FAILURE() << "the run went on after the signal";
    } catch (const Interrupted &e) {
        EXPECT_EQ(e.Signal(), sig);
        EXPECT_NE(std::string(e.what()).find("after 20 records; 20 complete records kept in '" +
                                             (tmp.path() / "cut.mtx.partial").string() +
                                             "': the same command with -r continues the run"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(tmp.path() / "cut.mtx"));
    const std::string full = MatrixBody(tmp.path() / "full.mtx");
    ASSERT_EQ(full.size(), 100u * 2 * 12);
    EXPECT_EQ(MatrixBody(tmp.path() / "cut.mtx.partial"), full.substr(0, 20 * 2 * 12));
    // Once more without -r: refused, the records kept.
    EXPECT_THROW(run("cut.mtx", false, -1), UserError);
    EXPECT_TRUE(fs::exists(tmp.path() / "cut.mtx.partial"));
    run("cut.mtx", true, -1);
    EXPECT_EQ(MatrixBody(tmp.path() / "cut.mtx"), full);
    EXPECT_FALSE(fs::exists(tmp.path() / "cut.mtx.partial"));
}

INSTANTIATE_TEST_SUITE_P(Faults, SignalStop, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto &info) {
                             return info.param == SIGINT ? "SIGINT" : "SIGTERM";
                         });

// An engine that fails in the middle of a run, as a GPU does when it is lost or out of memory
// (VK_CHECK's error): the run stops with that message, and the records written before it are
// kept for -r (which may finish on the CPU).
class LostGpu : public ContribEngine {
  public:
    std::string Label() const override { return "lost GPU"; }
    int Columns() const override { return 1; }
    size_t BatchRays() const override { return 8; }
    void Trace(const double *, size_t n, uint64_t first, int, double *records) override {
        if (first >= 64)
            ErrorExit(
                "Vulkan: vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX) failed "
                "(VK_ERROR_DEVICE_LOST: the GPU stopped or was reset)");
        for (size_t i = 0; i < 3 * n; ++i) records[i] += 1;
    }
};

TEST(Faults, LostGpuKeepsTheRecordsWritten) {
    TempDir tmp;
    const std::string out = (tmp.path() / "v.mtx").string();
    std::vector<std::string> header;
    const RcontribOptions o = ParseRcontribOptions(
        {"rcontrib-gpu", "-ff", "-c", "4", "-o", out, "-m", "sky", "room.rad"}, &header);
    LostGpu engine;
    RcontribOutputs outputs(o, engine.Columns(), header, "", engine.Label());
    size_t next = 0;
    try {
        TraceToOutputs(o, engine, outputs, [&](double ray[6]) {
            std::fill(ray, ray + 6, 0.0);
            ray[5] = 1;
            return ++next <= 400;
        });
        ADD_FAILURE() << "no error";
    } catch (const UserError &e) {
        EXPECT_NE(std::string(e.what()).find("VK_ERROR_DEVICE_LOST"), std::string::npos);
        // Blocks in flight when the error came are not written: at most the 16 records of the
        // rays before it, and the message says how many the file holds.
        const size_t records = MatrixBody(out + ".partial").size() / 12;
        EXPECT_GE(records, 1u);
        EXPECT_LE(records, 16u);
        EXPECT_NE(
            std::string(e.what()).find(std::to_string(records) + " complete records kept in '" +
                                       out + ".partial': the same command with -r continues"),
            std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(MatrixBody(out + ".partial").size() % 12, 0u);
}

// The same through the program: SIGTERM while it waits for rays from a pipe the producer keeps
// open, after a zero ray flushed the records before it. It stops at once (not when the pipe
// closes, 5 s later), ends by the signal (status 143 from the shell), and the partial files hold
// the 41 records. A -r that cannot open one output (another run holds it) leaves the other's
// records alone; then -r finishes both as an uninterrupted run would have.
TEST(Faults, SigtermToTheProgramKeepsItsRecords) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    const std::string first = Rays(81) + "0 0 0 0 0 0\n", rest = Rays(119);
    WriteFile(tmp.path() / "first", first);
    WriteFile(tmp.path() / "all", first + rest);
    const std::string cmd = std::string("rcontrib-gpu ") + kArgs + " -faf";
    const std::string outputs = " -o %s_%s.mtx -m sky -m grey room.rad";
    const auto run = [&](const std::string &prefix, const std::string &more) {
        std::string c = cmd + more + outputs;
        return c.replace(c.find("%s_"), 3, prefix + "_");
    };
    ASSERT_EQ(RunCommand(run("full", "") + " < all", tmp.path()).status, 0);
    // The producer waits until the flushed records are in the partial file, so the signal
    // never comes before the handler is in place.
    const CommandResult r = RunCommand(
        "mkfifo rays.fifo\n" + run("cut", "") +
            " < rays.fifo & pid=$!\n"
            "{ cat first; n=0; while [ $(stat -c %s cut_sky.mtx.partial 2>/dev/null || echo 0) "
            "-lt 984 ] && [ $n -lt 600 ]; do sleep 0.05; n=$((n+1)); done; kill -TERM $pid; "
            "sleep 5; touch late; } > rays.fifo &\n"
            "wait $pid; echo $?; [ -e late ] && echo late; wait",
        tmp.path());
    EXPECT_EQ(r.out, "143\n") << r.err;
    EXPECT_NE(r.err.find("stopped by SIGTERM after 41 records; 41 complete records kept in "
                         "'cut_sky.mtx.partial', 'cut_grey.mtx.partial': the same command with "
                         "-r continues the run"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp.path() / "cut_sky.mtx"));
    const auto kept = fs::file_size(tmp.path() / "cut_sky.mtx.partial");
    CommandResult again = RunCommand(
        "flock cut_grey.mtx.partial sleep 2 & sleep 0.5; " + run("cut", " -r") + " < all; wait",
        tmp.path());
    EXPECT_NE(again.err.find("another run is writing it"), std::string::npos) << again.err;
    ASSERT_TRUE(fs::exists(tmp.path() / "cut_sky.mtx.partial"));
    EXPECT_EQ(fs::file_size(tmp.path() / "cut_sky.mtx.partial"), kept);
    again = RunCommand(run("cut", " -r") + " < all", tmp.path());
    EXPECT_EQ(again.status, 0) << again.err;
    EXPECT_EQ(MatrixBody(tmp.path() / "cut_sky.mtx"), MatrixBody(tmp.path() / "full_sky.mtx"));
    EXPECT_EQ(MatrixBody(tmp.path() / "cut_grey.mtx"), MatrixBody(tmp.path() / "full_grey.mtx"));
    // One file under two names is refused before anything is written.
    again = RunCommand(cmd + " -se ./twice.mtx -o twice.mtx -m sky room.rad < all", tmp.path());
    EXPECT_EQ(again.status, 1);
    EXPECT_NE(again.err.find("name the same output file"), std::string::npos) << again.err;
}

// A file-size limit stands in for a full disk (no mount needed): the write error is a message,
// not SIGXFSZ's core dump, what was written stays in the partial file, and -r finishes it (a
// record cut short by the disk is traced again).
TEST(Faults, WriteErrorKeepsWhatWasWrittenForRecovery) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", Rays(4000));
    const std::string cmd = std::string("rcontrib-gpu ") + kArgs + " -faf";
    ASSERT_EQ(RunCommand(cmd + " -o full.mtx -m sky room.rad < rays", tmp.path()).status, 0);
    CommandResult r =
        RunCommand("ulimit -f 40 && " + cmd + " -o cut.mtx -m sky room.rad < rays", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("kept in 'cut.mtx.partial': the same command with -r continues"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp.path() / "cut.mtx"));
    const auto kept = fs::file_size(tmp.path() / "cut.mtx.partial");
    EXPECT_GT(kept, 1000u);
    EXPECT_LT(kept, 48000u);
    r = RunCommand(cmd + " -r -o cut.mtx -m sky room.rad < rays", tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(MatrixBody(tmp.path() / "cut.mtx"), MatrixBody(tmp.path() / "full.mtx"));
}

// A full device on the standard output: every program says so and exits 1.
TEST(Faults, FullDeviceIsAWriteError) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", Rays(4000));
    const std::string wea = (fs::path(DAYFLUX_TEST_DATA) / "sky" / "denver.wea").string();
    WriteFile(tmp.path() / "m.txt",
              "#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=1\nFORMAT=ascii\n\n"
              "1 2\n3 4\n");
    WriteFile(tmp.path() / "m3.txt",
              "#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n"
              "1 1 1 2 2 2\n3 3 3 4 4 4\n");
    for (const std::string &cmd :
         {std::string("rcontrib-gpu ") + kArgs + " -faf -m sky room.rad < rays",
          std::string("rmtxop -fa m.txt"), std::string("rmtxop -ff m.txt"),
          "gendaymtx -m 1 '" + wea + "'", std::string("dctimestep m3.txt m3.txt")}) {
        const CommandResult r = RunCommand(cmd + " > /dev/full", tmp.path());
        EXPECT_EQ(r.status, 1) << cmd;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << cmd << ": " << r.err;
    }
}

// A reader that closes the pipe ends the run by SIGPIPE (as RADIANCE's), at once rather than
// after every ray; the file output of the same run is not left under its name.
TEST(Faults, ClosedPipeEndsTheRunWithoutACompleteLookingFile) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", Rays(20000));
    const CommandResult r = RunCommand(std::string("{ rcontrib-gpu ") + kArgs +
                                           " -fa -m sky -o f.mtx -m grey room.rad < rays; "
                                           "echo $? > status; } | head -c 10 > /dev/null",
                                       tmp.path());
    EXPECT_EQ(ReadFile(tmp.path() / "status"), "141\n") << r.err;
    EXPECT_FALSE(fs::exists(tmp.path() / "f.mtx")) << r.err;
}

}  // namespace
}  // namespace dayflux::test
