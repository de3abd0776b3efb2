// genBSDF: RADIANCE's genBSDF (a system's Klems BSDF from its geometry, as WINDOW XML on the
// standard output) on rfluxmtx-gpu's engines (src/bsdf/genbsdf.h).
#include "bsdf/genbsdf.h"

#include <cstdio>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    const std::vector<std::string> args(argv, argv + argc);
    const GenBsdfOptions options = ParseGenBsdfOptions(args);
    const std::string xml = GenBsdf(options, args[0]);
    // Written whole once every matrix is made: a failed run leaves no partial XML.
    if (std::fwrite(xml.data(), 1, xml.size(), stdout) != xml.size() || std::fflush(stdout) != 0)
        ErrorExit("cannot write the XML to the standard output");
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
