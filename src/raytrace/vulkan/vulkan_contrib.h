// The GPU driver of the estimator core: the core as a compute shader (shaders/contrib.comp
// around raytrace/core), specialised to the run: its bin expressions and patterns compiled from
// calcomp to GLSL, only the features its scene needs compiled in; the packed tables resident on
// every device the choice gives, rays split between them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "raytrace/packing.h"

namespace dayflux {

// Returns nullptr and says why when no Vulkan device qualifies, or a bin or pattern expression
// has no GLSL form, or the scene is too large for a device's buffers. (UnsupportedOnGpu()
// decides first what the GPU's core does not trace.)
std::unique_ptr<ContribEngine> CreateVulkanContribEngine(
    const FlatScene &scene, const PackedScene &packed, const ContribOptions &options,
    const std::vector<TrackedModifier> &tracked, const MakeContext &make_context,
    const EngineOptions &engine, std::string *why);

}  // namespace dayflux
