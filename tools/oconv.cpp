// oconv: RADIANCE's octree maker, with its options (-f, -i, -b, -n, -r, -w), for RADIANCE's
// programs and ours, and byte for byte RADIANCE 5.4a's octree of the same scene.
// usage: oconv [-f][-w][-n N][-r N][-b x y z size | -i in.oct][-no_commands] file.. [-] > out.oct
#include "scene/oconv.h"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    OconvOptions o;
    int i = 1;
    const auto number = [&](const char *what) {
        double v;
        if (i + 1 >= argc || !ParseNumber(argv[i + 1], &v))
            ErrorExit(std::string("option ") + argv[i] + " needs " + what);
        ++i;
        return v;
    };
    const auto count = [&](const char *what) {
        const double v = number(what);
        if (!(v >= 1 && v <= 1e9 && v == static_cast<int>(v)))
            ErrorExit(std::string("option ") + argv[i - 1] + ": '" + argv[i] + "' is not " + what);
        return static_cast<int>(v);
    };
    // As oconv: options up to the first file (or "-", standard input), read by their letter.
    for (; i < argc && argv[i][0] == '-' && argv[i][1]; ++i) {
        if (std::string(argv[i]) == "-no_commands") {  // ours: the scene's "!commands" refused
            AllowCommandsInDataFiles(false);
            continue;
        }
        switch (argv[i][1]) {
            case 'i':
                if (i + 1 >= argc) ErrorExit("option -i needs an octree");
                o.input_octree = argv[++i];
                break;
            case 'b':
                for (double &c : o.bounds_origin) c = number("x y z size");
                o.bounds_size = number("x y z size");
                o.bounded = o.bounds_size > 0;
                if (!o.bounded) ErrorExit("-b: the cube's size must be positive");
                break;
            case 'n':
                o.set_limit = count("a positive whole number");
                break;
            case 'r':
                o.resolution = count("a positive whole number");
                break;
            case 'f':
                o.frozen = true;
                break;
            case 'w':
                o.warnings = false;
                break;
            default:
                ErrorExit(std::string("unknown option: '") + argv[i] + "'");
        }
    }
    const std::vector<std::string> files(argv + i, argv + argc);
    MakeOctree(files, o, CommandLine(argc, argv), [](std::string_view bytes) {
        if (std::fwrite(bytes.data(), 1, bytes.size(), stdout) != bytes.size())
            ErrorExit("write error on standard output");
    });
    if (std::fflush(stdout) != 0) ErrorExit("write error on standard output");
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
