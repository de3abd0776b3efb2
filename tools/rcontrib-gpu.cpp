// rcontrib-gpu: RADIANCE's rcontrib (contribution coefficients of modifiers to input rays) on
// dayflux's engines: the CPU with Embree, or a Vulkan GPU (src/rcontrib for the command line,
// outputs and records; src/raytrace for the engines). `rcontrib-gpu -devices` lists the Vulkan
// devices the build sees.
#include <cstdio>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/run.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    if (argc == 2 && std::string(argv[1]) == "-devices") {
        std::fputs(DescribeGpuDevices().c_str(), stdout);
        return 0;
    }
    std::vector<std::string> header_args = {argv[0]};
    const RcontribOptions o = ParseRcontribOptions(argc, argv, &header_args);
    RunRcontrib(o, header_args);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
