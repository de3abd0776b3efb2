// What the fuzz targets share: reading inputs the way the programs do (a UserError is a clean
// message, not a finding), scratch files for readers that take only a path, and the guard that
// keeps scene text from running shell commands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "scene/primitives.h"
#include "util/errors.h"

namespace dayflux::fuzz {

// Runs body as a program's RunTool() would: a UserError is the reader reporting bad input, which
// is what it should do. Anything else (another exception, a sanitizer report, an abort) escapes
// and is a finding.
template <class F>
void ExpectUserErrors(F &&body) {
    try {
        body();
    } catch (const UserError &) {
    }
}

inline std::string_view AsText(const uint8_t *data, size_t size) {
    return {reinterpret_cast<const char *>(data), size};
}

// A file of this process's own, rewritten with each input, for readers that only take paths.
// It is unlinked at once and named by its descriptor (/proc/self/fd/N), so that no run, however
// it ends (a crash, a fork-mode job killed at its time), leaves it behind.
class ScratchFile {
  public:
    ScratchFile();
    ~ScratchFile();
    ScratchFile(const ScratchFile &) = delete;
    ScratchFile &operator=(const ScratchFile &) = delete;

    // Replaces the file's content; returns its path.
    const std::string &Write(std::string_view data);

  private:
    int fd_ = -1;
    std::string path_;
};

// The one scene file the inputs may name in !xform lines (and unfrozen octrees may list): a
// few primitives and an rfluxmtx annotation, written once per process. The path is fixed so that
// seeds can name it.
inline constexpr const char *kPartFile = "/tmp/dayflux_fuzz_part.rad";
void WritePartFile();

// True where every '!' in text begins a line that the scene reader (and rfluxmtx's) would do
// in-process as "!xform" and whose files are all kPartFile. Anything else would reach /bin/sh
// (other commands, and xform lines with shell syntax or options only the real xform has), or
// read stdin ("!xform" without files), a device or another file of this machine.
bool OnlySafeCommands(std::string_view text);

// True if the scene has instances or meshes: Flatten() would open the files they name.
bool NamesFiles(const Scene &scene);

}  // namespace dayflux::fuzz
