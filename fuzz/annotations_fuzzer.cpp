// rfluxmtx's sender and receiver files: `#@rfluxmtx` annotations and the polygons, rings and
// sources after them, read by ReadReceivers and ReadSender, then each group's normal and up
// vector (the hemisphere's frame). They take a path, so each input is written to a scratch file;
// inputs whose '!' lines would reach the shell, stdin or files of this machine are left out
// (fuzz_util.h).
#include "fuzz_util.h"
#include "rfluxmtx/annotations.h"

namespace {

void Frame(const dayflux::FluxGroup &g) {
    double n[3], u[3];
    g.Normal(n);
    g.Up(u);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    dayflux::fuzz::WritePartFile();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string_view text = dayflux::fuzz::AsText(data, size);
    if (!dayflux::fuzz::OnlySafeCommands(text)) return -1;
    const std::string &path = file.Write(text);
    dayflux::fuzz::ExpectUserErrors([&] {
        for (const dayflux::FluxGroup &g : dayflux::ReadReceivers(path))
            dayflux::fuzz::ExpectUserErrors([&] { Frame(g); });
    });
    dayflux::fuzz::ExpectUserErrors([&] { Frame(dayflux::ReadSender(path)); });
    return 0;
}
