// No double in the GPU's shaders unless a run asks for one: every feature the core compiles in,
// with the standard bin functions, gives SPIR-V without the Float64 capability, which a device
// without shaderFloat64 (Apple's, Intel's) can run. (Compiling needs no device; every run also
// checks its SPIR-V, on its own traversal and stack, before it starts.)
#include <gtest/gtest.h>

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

// (One compile: the traversals and the stack's places add no arithmetic, and each compile of
// every feature takes glslang about 25 s.)
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

}  // namespace
}  // namespace dayflux
