// rtrace_dc-gpu: DAYSIM's rtrace_dc (daylight coefficients of sensors, sorted by sun modifier or
// by sky patch) on dayflux's engines, the CPU with Embree or a Vulkan GPU (src/daysim).
#include <string>
#include <vector>

#include "daysim/rtrace_dc.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    std::vector<std::string> header_args;
    const RtraceDcOptions o = ParseRtraceDcOptions({argv, argv + argc}, &header_args);
    RunRtraceDc(o, header_args);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
