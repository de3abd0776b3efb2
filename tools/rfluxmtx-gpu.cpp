// rfluxmtx-gpu: RADIANCE's rfluxmtx (flux transfer matrices between a sender's hemisphere and
// receivers' bins) on dayflux's engines (src/rfluxmtx/run.h).
#include <string>
#include <vector>

#include "rfluxmtx/run.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    RunRfluxmtx(std::vector<std::string>(argv, argv + argc));
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
