// rtrace_dc-gpu: DAYSIM's rtrace_dc (daylight coefficients of sensors, sorted by sun modifier or
// by sky patch) on dayflux's engines, the CPU with Embree or a Vulkan GPU (src/daysim).
#include <cstdio>
#include <string>
#include <vector>

#include "daysim/rtrace_dc.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    // DAYSIM's gen_dc records `rtrace_dc -version` in its files' headers.
    if (argc == 2 && std::string(argv[1]) == "-version") {
        std::puts("dayflux rtrace_dc-gpu (DAYSIM's rtrace_dc, DAYSIM 5.2's options and formats)");
        return 0;
    }
    std::vector<std::string> header_args;
    const RtraceDcOptions o = ParseRtraceDcOptions({argv, argv + argc}, &header_args);
    RunRtraceDc(o, header_args);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
