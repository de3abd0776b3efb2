#include "raytrace/backend.h"

#include <cstdlib>

#include "util/errors.h"

namespace dayflux {

std::string ChooseBackend(const std::string &requested) {
    std::string name = requested;
    if (name.empty()) {
        const char *env = std::getenv("DAYFLUX_BACKEND");
        name = env && *env ? env : "embree";
    }
    if (name != "embree" && name != "vulkan")
        ErrorExit("unknown backend '" + name + "' (embree or vulkan)");
    return name;
}

}  // namespace dayflux
