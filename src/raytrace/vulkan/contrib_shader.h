// The GPU driver's compute shader for one run: shaders/contrib.comp and the estimator core it
// includes (embedded in the program at build time, found by a shaderc includer), after the
// run's macros, the tracked modifiers' bin expressions and the scene's patterns generated from
// calcomp (cal/glsl.h). Compiled SPIR-V is cached on disk by its source.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "raytrace/packing.h"
#include "raytrace/vulkan/raytracing.h"

namespace dayflux {

// Invocations per work group, and the shader's sizes: its ray stack, and the rows of deeper
// hemispheres that keep RADIANCE's collision rule (up to kGpuDeepN cells a side, for the first
// kGpuDeepLevels bounces). The first hemisphere's rows: in scratch buffers (shaders/common.h),
// as many as each run's -ad needs; in private arrays, kGpuMaxRows (-ad up to 65536; beyond,
// no collision rule).
constexpr int kGpuLocalSize = 64;
constexpr int kGpuStackSize = 64;
constexpr int kGpuDeepN = 16;
constexpr int kGpuDeepLevels = 12;
constexpr int kGpuMaxRows = 256;

struct ContribShader {
    std::string source;  // without the #version line and extensions, which depend on the device
    // Per tracked modifier, its bin function (one per distinct expression and context), for
    // PackedScene::tracked's third entry.
    std::vector<int> bin_function;
};

// The shader's source for a run; false, with why, where GLSL cannot express a bin or a pattern.
bool MakeContribShader(const PackedScene &packed, const ContribOptions &options,
                       const std::vector<TrackedModifier> &tracked, const MakeContext &make_context,
                       const EngineOptions &engine, ContribShader *shader, std::string *why);

// What a device's SPIR-V depends on besides the run's source.
struct ShaderTarget {
    bool ray_queries = false;  // else our BVH walk
    bool scratch = false;      // the stack and rows in scratch buffers, else private arrays
    bool inf_nan = false;      // floats keep infinities and NaNs (GpuDevice::PreservesInfNan)
    vk::SpirvOptimization optimization = vk::SpirvOptimization::kPerformance;
};

// SPIR-V for a device, from the cache if it is there. replay: the kernel that traces logged rays
// again for their nearest hits alone (contrib.comp's DAYFLUX_REPLAY).
std::vector<uint32_t> CompileContribShader(const ContribShader &shader, const ShaderTarget &target,
                                           bool replay = false);

// SPIR-V of the second stage of a dispatch whose rays' slices it holds whole (GpuTasks: count a
// multiple of slices): each ray's record summed over its slices in their order, from
// kBindingAccum into kBindingSliceSums, so that one record a ray comes back rather than one a
// slice. Pairs or double accumulators (plain floats come back a slice at a time).
constexpr int kSliceSumLocalSize = 64;
std::vector<uint32_t> CompileSliceSumShader(GpuAccum accumulators);

}  // namespace dayflux
