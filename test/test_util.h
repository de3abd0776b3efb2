// Helpers shared by the tests: data paths, temporary folders, running the built programs.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace dayflux::test {

// The test data and the built programs, where the build put them, or where
// DAYFLUX_TEST_DATA_DIR and DAYFLUX_TEST_BIN_DIR say (a build copied to another machine:
// bench/gpu.sh).
inline std::filesystem::path FromEnvironment(const char *name, const char *built) {
    const char *v = std::getenv(name);
    return v && *v ? v : built;
}
inline std::filesystem::path DataDir() {
    return FromEnvironment("DAYFLUX_TEST_DATA_DIR", DAYFLUX_TEST_DATA);
}
inline std::filesystem::path BinDir() {
    return FromEnvironment("DAYFLUX_TEST_BIN_DIR", DAYFLUX_BIN_DIR);
}

// A fresh folder under the system temp directory, removed with the object.
class TempDir {
  public:
    TempDir();
    ~TempDir();
    const std::filesystem::path &path() const { return path_; }

  private:
    std::filesystem::path path_;
};

struct CommandResult {
    int status = 0;  // exit status
    std::string out, err;
};

// Runs a shell command in folder dir with the built programs first on PATH.
CommandResult RunCommand(const std::string &command, const std::filesystem::path &dir);

std::string ReadFile(const std::filesystem::path &p);
void WriteFile(const std::filesystem::path &p, const std::string &data);
// Header and data of a RADIANCE file without the lines that change from run to run
// (CAPDATE=, GMT=) or that dayflux adds deliberately (BigEndian=, see docs/compat.md).
std::string Comparable(const std::string &text);

}  // namespace dayflux::test
