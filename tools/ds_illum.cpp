// ds_illum: DAYSIM's annual illuminances (.ill) of a project from its daylight coefficients and
// weather (src/daysim/ds_illum.h): `ds_illum project.hea [-ext str]`.
#include "daysim/ds_illum.h"

#include <cstdio>
#include <string>

#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    // DAYSIM's gen_dc records `rtrace_dc -version` in its files' headers.
    if (argc == 2 && std::string(argv[1]) == "-version") {
        std::puts("dayflux ds_illum (DAYSIM's ds_illum, DAYSIM 5.2's options and formats)");
        return 0;
    }
    if (argc < 2 || argv[1][0] == '-') ErrorExit("usage: ds_illum project.hea [-ext str]");
    DsIllumOptions o;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-ext" && i + 1 < argc) {
            o.extension = argv[++i];
        } else if (a == "-dds") {
            ErrorExit("-dds: DAYSIM's DDS files are not supported");
        } else {
            ErrorExit("unknown option '" + a + "'");
        }
    }
    const DaysimProject p = ReadDaysimProject(argv[1]);
    if (p.where.count("time_step") == 0)
        Warning("no time_step in " + p.file +
                ": DAYSIM's 5 minutes taken (it moves the hours of "
                "sunrise and sunset)");
    RunDsIllum(p, o);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
