// rtrace-gpu: RADIANCE's (and Accelerad's) rtrace for daylighting's uses: radiance along rays,
// irradiance at sensors (-I) or at what rays meet (-i), with -o's values, on dayflux's engines,
// the CPU with Embree or a Vulkan GPU (src/rtrace).
#include <string>
#include <vector>

#include "rtrace/rtrace.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    std::vector<std::string> header_args;
    const RtraceOptions o = ParseRtraceOptions({argv, argv + argc}, &header_args);
    RunRtrace(o, header_args);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
