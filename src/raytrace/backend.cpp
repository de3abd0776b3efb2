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
    // The Vulkan backend is an integrator of its own (raytrace/vulkan/vulkan_contrib.h), not a
    // ray caster behind this interface: a program that gets here traces on the CPU.
    if (name == "vulkan") return CreateEmbreeBackend();
    ErrorExit("unknown backend '" + name + "' (embree or vulkan)");
}

}  // namespace dayflux
