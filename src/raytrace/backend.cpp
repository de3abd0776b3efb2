#include "raytrace/backend.h"

#include <cstdlib>

#include "util/errors.h"

namespace dayflux {

std::unique_ptr<Backend> CreateEmbreeBackend();

std::unique_ptr<Backend> CreateBackend(const std::string &requested) {
    std::string name = requested;
    if (name.empty()) {
        const char *env = std::getenv("DAYFLUX_BACKEND");
        name = env && *env ? env : "embree";
    }
    if (name == "embree") return CreateEmbreeBackend();
    if (name == "vulkan") {
        Warning("the Vulkan backend is not available yet; using Embree");
        return CreateEmbreeBackend();
    }
    ErrorExit("unknown backend '" + name + "' (embree or vulkan)");
}

}  // namespace dayflux
