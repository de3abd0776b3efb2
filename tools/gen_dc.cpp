// gen_dc: DAYSIM's daylight coefficients of a project file (src/daysim/gen_dc.h), traced by
// rtrace_dc-gpu's engine in this process: `gen_dc project.hea [-dir|-dif|-paste] [-h]
// [-ext str]`, with ours: [-backend embree|vulkan] [-device name] [-seed n] [-n threads].
#include "daysim/gen_dc.h"

#include <cstdio>
#include <cstring>
#include <string>

#include "rcontrib/options.h"
#include "util/errors.h"

namespace dayflux {
namespace {

[[noreturn]] void Usage() {
    ErrorExit(
        "usage: gen_dc project.hea [-dir|-dif|-paste] [-h] [-ext str] [-backend b] "
        "[-device d] [-seed n] [-n threads]");
}

int Main(int argc, char **argv) {
    // DAYSIM's gen_dc records `rtrace_dc -version` in its files' headers.
    if (argc == 2 && std::string(argv[1]) == "-version") {
        std::puts("dayflux gen_dc (DAYSIM's gen_dc, DAYSIM 5.2's options and formats)");
        return 0;
    }
    if (argc < 2 || argv[1][0] == '-') Usage();
    GenDcOptions g;
    bool some = false;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        const auto value = [&]() -> std::string {
            if (i + 1 >= argc) ErrorExit(a + ": missing argument");
            return argv[++i];
        };
        if (a == "-dir" || a == "-dif" || a == "-paste") {
            if (!some) g.direct = g.diffuse = g.merge = false;
            some = true;
            (a == "-dir" ? g.direct : a == "-dif" ? g.diffuse : g.merge) = true;
        } else if (a == "-h") {
            g.show_commands = true;
        } else if (a == "-ext") {
            g.extension = value();
        } else if (a == "-f") {
            value();  // DAYSIM's bin folder: nothing runs outside this process
        } else if (a == "-seed" || a == "-n" || IsEngineOption(a)) {
            g.engine_args.push_back(a);
            g.engine_args.push_back(value());
        } else if (a == "-dds" || a == "-substract" || a == "-add") {
            ErrorExit(a + ": DAYSIM's DDS files are not supported");
        } else {
            ErrorExit("unknown option '" + a + "'");
        }
    }
    RunGenDc(ReadDaysimProject(argv[1]), g);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
