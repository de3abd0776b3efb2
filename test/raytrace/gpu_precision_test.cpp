// No double in the GPU's shaders unless a run asks for one: every feature the core compiles in,
// with the standard bin functions, gives SPIR-V without the Float64 capability, which a device
// without shaderFloat64 (Apple's, Intel's) can run. (Compiling needs no device; every run also
// checks its SPIR-V, on its own traversal and stack, before it starts.)
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "raytrace/vulkan/contrib_shader.h"
#include "raytrace/vulkan/raytracing.h"

namespace dayflux {
namespace {

std::string Lib(const char *f) { return std::string(DAYFLUX_LIB_DIR) + "/" + f; }

// Every DAYFLUX_* feature, and Reinhart and Klems bins (kbin unrolls kfindrow's recursion).
ContribShader EveryFeature(const EngineOptions &engine) {
    PackedScene packed;
    packed.bsdf = packed.dielectric = packed.local_sources = packed.mirror_images = true;
    packed.inside = packed.aperture = true;
    ContribOptions options;
    options.ambient_subsamples = 4;
    std::vector<TrackedModifier> tracked(2);
    tracked[0].name = "sky";
    tracked[0].bin_expression = "rbin";
    tracked[0].nbins = 577;
    tracked[1].name = "window";
    tracked[1].bin_expression = "kbin(0,0,1, 0,1,0)";
    tracked[1].nbins = 145;
    tracked[1].first_column = 577;
    const MakeContext make_context = [](int k) {
        auto cx = std::make_unique<cal::Context>();
        cx->LoadRayInit();
        if (k == 0) {
            cx->Set("MF", 2, true);
            cx->LoadFile(Lib("reinhart.cal"));
        } else {
            cx->LoadFile(Lib("klems_full.cal"));
        }
        return cx;
    };
    ContribShader shader;
    std::string why;
    EXPECT_TRUE(MakeContribShader(packed, options, tracked, make_context, engine, &shader, &why))
        << why;
    return shader;
}

// (One compile: the traversals and the stack's places add no arithmetic, and spirv-opt's -O on
// every feature takes about 7 s, cold.)
TEST(GpuPrecision, NoDoubleInTheShadersByDefault) {
    EXPECT_FALSE(vk::GpuDevice::UsesFloat64(
        CompileContribShader(EveryFeature(EngineOptions{}), ShaderTarget{false, true})));
    EXPECT_FALSE(vk::GpuDevice::UsesFloat64(CompileSliceSumShader(GpuAccum::kPair)));
}

// The check itself finds doubles (the calcomp code in double: cal/glsl_test.cpp).
TEST(GpuPrecision, DoublesAreFound) {
    EXPECT_TRUE(vk::GpuDevice::UsesFloat64(CompileSliceSumShader(GpuAccum::kDouble)));
    EXPECT_TRUE(vk::GpuDevice::UsesFloat64(vk::GpuDevice::CompileGlsl(
        "#version 450\nlayout(local_size_x = 1) in;\n"
        "layout(std430, binding = 0) buffer Out { float v[]; };\n"
        "void main() { double d = double(v[0]); v[0] = float(d * d); }\n",
        "double")));
}

// How many times each named function would be compiled once every call is inlined, as GPU
// compilers inline them: the SPIR-V's call graph from its entry point (spirv-opt's "none" keeps
// the functions and their OpNames).
std::map<std::string, uint64_t> InlinedCopies(const std::vector<uint32_t> &spirv) {
    constexpr uint32_t kOpName = 5, kOpFunction = 54, kOpFunctionEnd = 56, kOpFunctionCall = 57,
                       kOpEntryPoint = 15;
    std::map<uint32_t, std::string> names;
    std::map<uint32_t, std::vector<uint32_t>> calls;  // a function's callees, once a call
    uint32_t entry = 0, function = 0;
    vk::GpuDevice::ForEachInstruction(spirv, [&](uint32_t op, const uint32_t *w, uint32_t) {
        if (op == kOpName) {
            names[w[1]] = reinterpret_cast<const char *>(&w[2]);
        } else if (op == kOpEntryPoint) {
            entry = w[2];
        } else if (op == kOpFunction) {
            function = w[2];
        } else if (op == kOpFunctionEnd) {
            function = 0;
        } else if (op == kOpFunctionCall && function != 0) {
            calls[function].push_back(w[3]);
        }
        return true;
    });
    std::map<std::string, uint64_t> copies;
    // (the graph has no cycles: GLSL has no recursion)
    std::vector<uint32_t> todo{entry};
    while (!todo.empty()) {
        const uint32_t f = todo.back();
        todo.pop_back();
        const std::string name = names[f].substr(0, names[f].find('('));
        ++copies[name];
        for (uint32_t callee : calls[f]) todo.push_back(callee);
    }
    return copies;
}

// GPU compilers inline every call, so the shading code must be reached from one call of the walk
// and the bins from one call of their evaluation, on both engines: three walks made NVIDIA
// compile for 15-35 s and lavapipe's test suite take 610 s (core/README.md).
TEST(GpuPrecision, OneWalkAndOneBinEvaluationInTheShader) {
    for (GpuEngine engine : {GpuEngine::kTasks, GpuEngine::kPaths}) {
        EngineOptions options;
        options.gpu_engine = engine;
        ShaderTarget target{false, true};
        target.optimization = vk::SpirvOptimization::kNone;
        std::map<std::string, uint64_t> copies =
            InlinedCopies(CompileContribShader(EveryFeature(options), target));
        const char *what = engine == GpuEngine::kTasks ? "tasks" : "paths";
        EXPECT_EQ(copies["main"], 1u) << what;     // (the reader found the entry point)
        EXPECT_EQ(copies["NextRay"], 1u) << what;  // (the walk: contrib.comp's Run)
        EXPECT_EQ(copies["ShadeMet"], 1u) << what;
        EXPECT_EQ(copies["AddContribution"], 1u) << what;
        EXPECT_EQ(copies["EvalBin"], 1u) << what;
        EXPECT_EQ(copies["AmbientStep"], 1u) << what;  // (the rows before a slice's too)
        EXPECT_GE(copies["Spawn"], 1u) << what;
    }
}

}  // namespace
}  // namespace dayflux
