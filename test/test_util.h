// Helpers shared by the tests: data paths, temporary folders, running the built programs.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

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

// A grey floor under a glowing sky dome: the smallest scene a run of rcontrib-gpu traces
// (modifiers sky, a glow source, and grey, a plastic).
inline constexpr const char *kFloorUnderSky =
    "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
    "grey polygon floor 0 0 12 -5 -5 -1 5 -5 -1 5 5 -1 -5 5 -1\n"
    "void glow sky 0 0 4 1 1 1 0\nsky source dome 0 0 4 0 0 1 180\n";

// The data of a RADIANCE matrix file after its header ("" without one): runs compared
// without their header's dates.
std::string MatrixBody(const std::filesystem::path &p);

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

// dayflux's folder of RADIANCE's program names (lib/dayflux/radiance/bin).
inline std::filesystem::path RadianceNames() {
    return BinDir() / ".." / "lib" / "dayflux" / "radiance" / "bin";
}
// Runs a command with dayflux alone under RADIANCE's names on PATH: that folder, /usr/bin and
// /bin (no RADIANCE anywhere, as on a machine with dayflux alone installed).
inline CommandResult RunWithDayfluxAlone(const std::string &command,
                                         const std::filesystem::path &dir) {
    return RunCommand("PATH='" + RadianceNames().string() + "':/usr/bin:/bin; " + command, dir);
}

std::string ReadFile(const std::filesystem::path &p);
// A -target_report file's sensors, in order: the samples each took and its estimated error.
struct TargetReportSensor {
    int samples;
    double error;
};
std::vector<TargetReportSensor> ReadTargetReport(const std::filesystem::path &p);
void WriteFile(const std::filesystem::path &p, const std::string &data);
// Header and data of a RADIANCE file without the lines that change from run to run
// (CAPDATE=, GMT=) or that dayflux adds deliberately (BigEndian=, see docs/compat.md).
std::string Comparable(const std::string &text);

}  // namespace dayflux::test
