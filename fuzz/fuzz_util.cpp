#include "fuzz_util.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "scene/reader.h"

namespace dayflux::fuzz {

namespace {

// Two materials and a polygon for -m to replace, one surface of each kind that rfluxmtx counts,
// and the annotation it wants before them.
constexpr const char *kPartText =
    "void plastic white 0 0 5 .5 .5 .5 0 0\n"
    "void glow sky 0 0 4 1 1 1 0\n"
    "#@rfluxmtx h=kq u=+Y o=out.mtx\n"
    "white polygon floor 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0\n"
    "white ring disc 0 0 8 0 0 1 0 0 1 0 .5\n"
    "sky source sun 0 0 4 0 0 1 .5\n";

[[noreturn]] void Fail(const char *what) {
    std::perror(what);
    std::abort();
}

}  // namespace

ScratchFile::ScratchFile() {
    const char *dir = std::getenv("TMPDIR");
    std::string name = std::string(dir && *dir ? dir : "/tmp") + "/dayflux_fuzz_XXXXXX";
    fd_ = mkstemp(name.data());
    if (fd_ < 0) Fail("dayflux fuzz: cannot make a scratch file");
    unlink(name.c_str());
    path_ = "/proc/self/fd/" + std::to_string(fd_);
}

ScratchFile::~ScratchFile() { close(fd_); }

const std::string &ScratchFile::Write(std::string_view data) {
    if (ftruncate(fd_, 0) != 0) Fail("dayflux fuzz: cannot empty the scratch file");
    for (size_t done = 0; done < data.size();) {
        const ssize_t n = pwrite(fd_, data.data() + done, data.size() - done, done);
        if (n <= 0) Fail("dayflux fuzz: cannot write the scratch file");
        done += n;
    }
    return path_;
}

void WritePartFile() {
    // Written beside it and renamed, so that targets running at once never read half a file.
    std::string temp = std::string(kPartFile) + ".XXXXXX";
    const int fd = mkstemp(temp.data());
    const bool written = fd >= 0 && write(fd, kPartText, std::strlen(kPartText)) ==
                                        static_cast<ssize_t>(std::strlen(kPartText));
    if (fd >= 0) close(fd);
    if (!written || std::rename(temp.c_str(), kPartFile) != 0)
        Fail("dayflux fuzz: cannot write the part file");
}

bool OnlySafeCommands(std::string_view text) {
    for (size_t at = text.find('!'); at != std::string_view::npos; at = text.find('!', at + 1)) {
        const size_t end = text.find('\n', at);
        const std::string command(
            text.substr(at + 1, end == std::string_view::npos ? end : end - at - 1));
        // The scene reader continues a command after a trailing backslash; rfluxmtx's does not.
        // Neither matters here: such inputs are left out.
        if (!command.empty() && command.back() == '\\') return false;
        XformCommand xform;
        try {
            if (!ParseXformCommand(command, FileLoc{"fuzz", 1}, &xform)) return false;
        } catch (const UserError &) {
            return false;
        }
        for (const std::string &f : xform.files)
            if (f != kPartFile) return false;
    }
    return true;
}

bool NamesFiles(const Scene &scene) {
    for (const Primitive &p : scene.objects)
        if (p.type == "instance" || p.type == "mesh") return true;
    return false;
}

}  // namespace dayflux::fuzz
