// Issue 23's runs split across processes: a sensor file split into shards (examples/shards),
// each traced on its own with -first_record, merged with rmtxcat, is byte for byte the matrix
// of one run with the same -seed, whichever engine ran the shards (GNU parallel, locally and
// over ssh, make -j, a Slurm array on a cluster of one node, and task by task as its dry run);
// a missing shard stops the merge.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "test_util.h"

namespace dayflux::test {
namespace {

namespace fs = std::filesystem;

const char *const kRoom = kFloorUnderSky;

// Two rays a record (-c 2), so the shards' first records are half their first lines.
const std::string kArgs =
    "-seed 5 -faf -c 2 -ab 2 -ad 64 -lw 1e-4 -b 'if(Dz-.5,0,1)' -bn 2 -m sky room.rad";

class Shards : public ::testing::Test {
  protected:
    void SetUp() override {
        WriteFile(tmp_.path() / "room.rad", kRoom);
        std::ostringstream s;
        for (int i = 0; i < 610; ++i)
            s << "0 0 " << (i % 37) * 0.02 << " 0 " << (i % 11) * 0.1 << " 1\n";
        WriteFile(tmp_.path() / "sensors", s.str());
        const CommandResult r = Run("rcontrib-gpu " + kArgs + " < sensors > whole.mtx");
        ASSERT_EQ(r.status, 0) << r.err;
        whole_ = MatrixBody(tmp_.path() / "whole.mtx");
        ASSERT_EQ(whole_.size(), 305u * 2 * 12);
    }
    CommandResult Run(const std::string &command) {
        return RunCommand("PATH='" + Scripts().string() + "':\"$PATH\" && " + command, tmp_.path());
    }
    static fs::path Scripts() { return fs::path(DAYFLUX_LIB_DIR) / ".." / "examples" / "shards"; }
    // The scripts that start servers of a test's own (Slurm, sshd).
    static fs::path Servers() { return fs::path(DAYFLUX_LIB_DIR) / ".." / "test" / "tools"; }
    // Why such servers cannot run here ("" if they can): `installed` fails, or this is not root.
    std::string NoServers(const std::string &installed, const std::string &what) {
        if (RunCommand(installed, tmp_.path()).status != 0)
            return what + " is not installed (tools/setup.sh --tests installs it)";
        if (RunCommand("test \"$(id -u)\" = 0", tmp_.path()).status != 0)
            return "servers of the test's own need root";
        return "";
    }
    TempDir tmp_;
    std::string whole_;
};

TEST_F(Shards, GnuParallelMergesToTheSingleRun) {
    if (RunCommand("command -v parallel", tmp_.path()).status != 0)
        GTEST_SKIP() << "GNU parallel is not installed (tools/setup.sh installs it)";
    CommandResult r = Run("split_sensors.sh sensors 150 shards 2");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "5 shards of 150 lines in shards\n");
    EXPECT_TRUE(fs::exists(tmp_.path() / "shards" / "shard_000000000225.pts"));
    r = Run("parallel -j 3 --halt now,fail=1 -q trace_shard.sh {} {.}.mtx " + kArgs +
            " ::: shards/shard_*.pts && merge_shards.sh shards merged.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(MatrixBody(tmp_.path() / "merged.mtx") == whole_);
    EXPECT_NE(ReadFile(tmp_.path() / "merged.mtx").find("NROWS=305\n"), std::string::npos);
}

// The recipe for hosts without a shared file system, over ssh to this machine (an sshd of the
// test's own, test/tools/local_sshd.sh): each shard sent with the scene to the host's folder
// (here host/), traced there, its matrix sent back, the files removed.
TEST_F(Shards, GnuParallelOverSshMergesToTheSingleRun) {
    const std::string no = NoServers("command -v parallel && test -x /usr/sbin/sshd",
                                     "GNU parallel or openssh-server");
    if (!no.empty()) GTEST_SKIP() << no;
    ASSERT_EQ(Run("split_sensors.sh sensors 210 shards 2").status, 0);
    WriteFile(
        tmp_.path() / "over_ssh.sh",
        "set -e\nparallel -S 2/$DAYFLUX_TEST_SSH_LOGIN --ssh \"$DAYFLUX_TEST_SSH\" "
        "--workdir \"$PWD/host\" --env PATH --basefile room.rad --transferfile {} --return {.}.mtx "
        "--cleanup --halt now,fail=1 -q trace_shard.sh {} {.}.mtx " +
            kArgs + " ::: shards/shard_*.pts\nmerge_shards.sh shards ssh.mtx\n");
    const CommandResult r =
        Run("timeout 300 '" + (Servers() / "local_sshd.sh").string() + "' sshd bash over_ssh.sh");
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    EXPECT_TRUE(MatrixBody(tmp_.path() / "ssh.mtx") == whole_);
    // Over ssh, and the host's folder left empty (--cleanup).
    EXPECT_NE(ReadFile(tmp_.path() / "sshd" / "sshd.log").find("Accepted publickey"),
              std::string::npos);
    EXPECT_EQ(Run("find host -type f 2>/dev/null | wc -l").out, "0\n");
}

TEST_F(Shards, MakeMergesToTheSingleRun) {
    ASSERT_EQ(Run("split_sensors.sh sensors 100 shards 2").status, 0);
    const CommandResult r = Run("make -s -j 3 -f '" + (Scripts() / "Makefile").string() +
                                "' DIR=shards OUT=made.mtx ARGS=\"" + kArgs + "\"");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(MatrixBody(tmp_.path() / "made.mtx") == whole_);
}

// The job array's script run as Slurm would run each task (no Slurm needed), then the merge.
TEST_F(Shards, SlurmArrayTasksMergeToTheSingleRun) {
    ASSERT_EQ(Run("split_sensors.sh sensors 200 shards 2").status, 0);
    const CommandResult r = Run(
        "for t in 0 1 2 3; do SLURM_ARRAY_TASK_ID=$t SLURM_CPUS_PER_TASK=1 DAYFLUX_SHARDS_DIR='" +
        Scripts().string() + "' bash '" + (Scripts() / "shards.sbatch").string() + "' shards " +
        kArgs + " || exit 1; done && merge_shards.sh shards slurm.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(MatrixBody(tmp_.path() / "slurm.mtx") == whole_);
}

// The same on a real Slurm: a cluster of one node started from Debian's packages
// (test/tools/single_node_slurm.sh), the array submitted as docs/shards.md says, the merge a job
// that waits for every task.
TEST_F(Shards, SlurmClusterRunsTheArrayAndTheMerge) {
    const std::string no = NoServers("test -x /usr/sbin/slurmctld", "Slurm");
    if (!no.empty()) GTEST_SKIP() << no;
    ASSERT_EQ(Run("split_sensors.sh sensors 200 shards 2").status, 0);
    WriteFile(tmp_.path() / "submit.sh",
              "set -e\nn=$(ls shards/shard_*.pts | wc -l)\n"
              "job=$(sbatch --parsable --array=0-$((n - 1)) '" +
                  (Scripts() / "shards.sbatch").string() + "' shards " + kArgs +
                  ")\n"
                  "sbatch --wait --kill-on-invalid-dep=yes --dependency=afterok:$job "
                  "--wrap 'merge_shards.sh shards slurm.mtx'\n");
    const CommandResult r =
        Run("export DAYFLUX_SHARDS_DIR='" + Scripts().string() + "' && timeout 300 '" +
            (Servers() / "single_node_slurm.sh").string() + "' slurm bash submit.sh");
    ASSERT_EQ(r.status, 0) << r.err << r.out << ReadFile(tmp_.path() / "slurm" / "slurmctld.log");
    EXPECT_TRUE(MatrixBody(tmp_.path() / "slurm.mtx") == whole_);
    // Four array tasks ran, each with its own log (shards.sbatch's --output).
    EXPECT_EQ(Run("ls slurm-*_[0-3].log | wc -l").out, "4\n");
}

// rfluxmtx-gpu passes -first_record on in pass-through mode (V from a sensor file), and refuses
// it with a sender, whose samples are not read from a file that could be split.
TEST_F(Shards, RfluxmtxPassThroughShardIsTheSingleRunsTail) {
    WriteFile(tmp_.path() / "receiver.rad",
              "#@rfluxmtx h=u u=+Y\nvoid glow skyr 0 0 4 1 1 1 0\nskyr source s 0 0 4 0 0 1 180\n");
    const std::string rflux = "rfluxmtx-gpu -seed 5 -I+ -ab 2 -ad 64 -lw 1e-4 -faf ";
    ASSERT_EQ(Run(rflux + "- receiver.rad room.rad < sensors > all.mtx").status, 0);
    const CommandResult r = Run("sed -n 301,610p sensors | " + rflux +
                                "-first_record 300 - receiver.rad room.rad > tail.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string all = MatrixBody(tmp_.path() / "all.mtx"),
                      tail = MatrixBody(tmp_.path() / "tail.mtx");
    ASSERT_EQ(all.size(), 610u * 12);
    EXPECT_TRUE(tail == all.substr(300 * 12));
    const CommandResult refused =
        Run("rfluxmtx-gpu -first_record 3 -c 10 receiver.rad receiver.rad room.rad");
    EXPECT_EQ(refused.status, 1);
    EXPECT_NE(refused.err.find("-first_record shards the rays read in pass-through mode"),
              std::string::npos)
        << refused.err;
}

TEST_F(Shards, MissingOrMismatchedShardsStopTheMerge) {
    ASSERT_EQ(Run("split_sensors.sh sensors 200 shards 2").status, 0);
    ASSERT_EQ(
        Run("for s in shards/shard_*.pts; do trace_shard.sh $s ${s%.pts}.mtx " + kArgs + "; done")
            .status,
        0);
    fs::remove(tmp_.path() / "shards" / "shard_000000000100.mtx");
    CommandResult r = Run("merge_shards.sh shards merged.mtx");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("shard 'shards/shard_000000000100.pts' has no matrix"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp_.path() / "merged.mtx"));
    // A shard of other columns (another -bn) is named by rmtxcat.
    r =
        Run("rcontrib-gpu -seed 5 -faf -c 2 -m sky room.rad < shards/shard_000000000100.pts > "
            "shards/shard_000000000100.mtx && merge_shards.sh shards merged.mtx");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("shard_000000000100.mtx: 1 columns of 3 components, where"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp_.path() / "merged.mtx"));
    // A shard cut inside a record (-c 2, three rays) would merge a row too many: an error.
    r = Run("head -n 3 sensors | rcontrib-gpu -first_record 4 " + kArgs + " > odd.mtx");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("the input ends 1 rays into a record of 2 (-c): a shard"),
              std::string::npos)
        << r.err;
    // Thousands of shards merge with one open at a time.
    r =
        Run("for k in $(seq 1 100); do printf '#?RADIANCE\\nNCOLS=2\\nNCOMP=1\\nFORMAT=ascii"
            "\\n\\n%d %d\\n' $k $k > m$k.txt; done; ulimit -n 40; rmtxcat -h m*.txt | wc -l");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "100\n") << r.err;
    r = Run("split_sensors.sh sensors 101 odd 2");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("must be a positive multiple of RAYS_PER_RECORD (2)"), std::string::npos);
}

}  // namespace
}  // namespace dayflux::test
