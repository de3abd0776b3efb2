// OutputFile on outputs that are not regular files (issue 41): a FIFO, a device node, a symbolic
// link and a descriptor's name are written, never replaced; regular files keep their rename.
#include "util/files.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "test_util.h"

namespace dayflux {
namespace {

namespace fs = std::filesystem;
using test::ReadFile;
using test::TempDir;
using test::WriteFile;

void WriteAndCommit(const std::string &spec, const std::string &bytes) {
    OutputFile out(spec);
    out.Write(bytes);
    out.Commit();
}

TEST(OutputFile, RegularFileIsWrittenBesideAndRenamedOn) {
    TempDir tmp;
    const std::string name = (tmp.path() / "out").string();
    WriteFile(name, "old");
    {
        OutputFile out(name);
        out.Write("new");
        EXPECT_EQ(ReadFile(name), "old");  // untouched until the commit
        EXPECT_TRUE(fs::exists(name + ".partial"));
        out.Commit();
    }
    EXPECT_EQ(ReadFile(name), "new");
    EXPECT_FALSE(fs::exists(name + ".partial"));
}

TEST(OutputFile, FifoIsWrittenToItsReaderAndStaysAFifo) {
    TempDir tmp;
    const std::string fifo = (tmp.path() / "fifo").string();
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    // The reader opened first, without waiting, so that a writer never waits either.
    const int reader = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    ASSERT_GE(reader, 0);
    WriteAndCommit(fifo, "records\n");
    char got[64] = {};
    EXPECT_EQ(read(reader, got, sizeof got), 8);
    close(reader);
    EXPECT_STREQ(got, "records\n");
    struct stat st;
    ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode));
    EXPECT_FALSE(fs::exists(fifo + ".partial"));
}

// The node /dev/null is (1,3), made in the test's own folder: only root may make it.
TEST(OutputFile, DeviceNodeIsWrittenAndStaysADevice) {
    if (geteuid() != 0) GTEST_SKIP() << "mknod of a character device needs root";
    TempDir tmp;
    const std::string null = (tmp.path() / "null").string();
    ASSERT_EQ(mknod(null.c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);
    WriteAndCommit(null, std::string(1 << 16, 'x'));
    struct stat st;
    ASSERT_EQ(lstat(null.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
    EXPECT_EQ(st.st_rdev, makedev(1, 3));
    EXPECT_FALSE(fs::exists(null + ".partial"));
}

// As RADIANCE's fopen() does: through the link, its partial file beside the target.
TEST(OutputFile, SymbolicLinkIsWrittenThroughToItsTarget) {
    TempDir tmp;
    fs::create_directory(tmp.path() / "data");
    WriteFile(tmp.path() / "data" / "real", "old");
    fs::create_symlink("data/real", tmp.path() / "link");
    fs::create_symlink("link", tmp.path() / "link2");  // a chain, each relative to its folder
    const std::string link2 = (tmp.path() / "link2").string();
    {
        OutputFile out(link2);
        out.Write("new");
        EXPECT_TRUE(fs::exists(tmp.path() / "data" / "real.partial"));
        EXPECT_FALSE(fs::exists(link2 + ".partial"));
        EXPECT_EQ(OutputFile::PartialName(link2), (tmp.path() / "data" / "real.partial").string());
        out.Commit();
    }
    EXPECT_TRUE(fs::is_symlink(tmp.path() / "link"));
    EXPECT_TRUE(fs::is_symlink(link2));
    EXPECT_EQ(ReadFile(tmp.path() / "data" / "real"), "new");
    // A dangling link makes its target.
    fs::create_symlink("made", tmp.path() / "dangling");
    WriteAndCommit((tmp.path() / "dangling").string(), "made");
    EXPECT_TRUE(fs::is_symlink(tmp.path() / "dangling"));
    EXPECT_EQ(ReadFile(tmp.path() / "made"), "made");
}

// /dev/fd/N is the descriptor itself: a shell's ">>" keeps what the file held.
TEST(OutputFile, DescriptorNameWritesTheOpenFileAtItsOffset) {
    TempDir tmp;
    const std::string file = (tmp.path() / "appended").string();
    WriteFile(file, "before\n");
    const int fd = open(file.c_str(), O_WRONLY | O_APPEND);
    ASSERT_GE(fd, 0);
    WriteAndCommit("/dev/fd/" + std::to_string(fd), "after\n");
    close(fd);
    EXPECT_EQ(ReadFile(file), "before\nafter\n");
    EXPECT_FALSE(fs::exists("/dev/fd/" + std::to_string(fd) + ".partial"));
}

TEST(OutputFile, DirectoriesAndLinkLoopsAreRefused) {
    TempDir tmp;
    fs::create_symlink("loop2", tmp.path() / "loop1");
    fs::create_symlink("loop1", tmp.path() / "loop2");
    for (const auto &[name, said] :
         {std::pair{tmp.path().string(), "Is a directory"},
          std::pair{(tmp.path() / "loop1").string(), "too many levels of symbolic links"}}) {
        try {
            OutputFile out(name);
            ADD_FAILURE() << name << " was opened";
        } catch (const UserError &e) {
            EXPECT_NE(std::string(e.what()).find(said), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace dayflux
