// Ray queries against a small hand-checked scene on a Vulkan device (lavapipe in CI).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "raytrace/vulkan/raytracing.h"

namespace dayflux::test {
namespace {

// For each ray (origin, direction as two vec4s) the committed hit: t, primitive index, hit flag.
// Indexes with y as the header asks, so it stays right when Run spills groups into y.
std::string TraceShader(int local_size_x) {
    return "#version 460\n"
           "#extension GL_EXT_ray_query : require\n"
           "layout(local_size_x = " +
           std::to_string(local_size_x) +
           ") in;\n"
           "layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;\n"
           "layout(std430, set = 0, binding = 1) readonly buffer Rays { vec4 rays[]; };\n"
           "struct Hit { float t; int primitive; int hit; int pad; };\n"
           "layout(std430, set = 0, binding = 2) writeonly buffer Hits { Hit hits[]; };\n"
           "void main() {\n"
           "  uint i = gl_GlobalInvocationID.x +\n"
           "           gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;\n"
           "  if (i >= uint(rays.length()) / 2u) return;\n"
           "  rayQueryEXT q;\n"
           "  rayQueryInitializeEXT(q, scene, gl_RayFlagsOpaqueEXT, 0xff, rays[2 * i].xyz, 1e-6,\n"
           "                        rays[2 * i + 1].xyz, 1e30);\n"
           "  while (rayQueryProceedEXT(q)) {}\n"
           "  if (rayQueryGetIntersectionTypeEXT(q, true) ==\n"
           "      gl_RayQueryCommittedIntersectionTriangleEXT)\n"
           "    hits[i] = Hit(rayQueryGetIntersectionTEXT(q, true),\n"
           "                  rayQueryGetIntersectionPrimitiveIndexEXT(q, true), 1, 0);\n"
           "  else\n"
           "    hits[i] = Hit(-1.0, -1, 0, 0);\n"
           "}\n";
}

struct Ray {
    float ox, oy, oz, dx, dy, dz;
};

struct Hit {
    float t;
    int32_t primitive;
    int32_t hit;
    int32_t pad;
};

// The unit square in z = 1 as triangles 0 (below the diagonal x = y) and 1 (above it), plus
// triangle 2 in z = 3 over y <= x - 0.5, x <= 2, which overlaps the square's corner near (1, 0).
// dz shifts the whole scene up.
void SquareScene(float dz, std::vector<float> *positions, std::vector<uint32_t> *indices) {
    *positions = {0,      0,   1 + dz, 1,      0, 1 + dz, 1,      1, 1 + dz, 0,     1,
                  1 + dz, 0.5, 0,      3 + dz, 2, 0,      3 + dz, 2, 1.5,    3 + dz};
    *indices = {0, 1, 2, 0, 2, 3, 4, 5, 6};
}

class VulkanRayQuery : public testing::Test {
  protected:
    static void SetUpTestSuite() {
        std::string why;
        device_ = vk::GpuDevice::Open(&why).release();
        if (!device_) skip_reason_ = why;
    }
    static void TearDownTestSuite() {
        delete device_;
        device_ = nullptr;
    }
    void SetUp() override {
        if (!device_) GTEST_SKIP() << "no Vulkan device with ray queries: " << skip_reason_;
    }

    static std::vector<Hit> Trace(const std::vector<uint32_t> &spirv, int local_size_x,
                                  const std::vector<Ray> &rays) {
        std::vector<float> in;
        for (const Ray &r : rays) in.insert(in.end(), {r.ox, r.oy, r.oz, 0, r.dx, r.dy, r.dz, 0});
        std::vector<uint8_t> in_bytes(in.size() * sizeof(float)),
            out_bytes(rays.size() * sizeof(Hit));
        std::memcpy(in_bytes.data(), in.data(), in_bytes.size());
        device_->Run(spirv, static_cast<uint32_t>(rays.size()), local_size_x,
                     {vk::GpuDevice::In(&in_bytes), vk::GpuDevice::InOut(&out_bytes)});
        std::vector<Hit> hits(rays.size());
        std::memcpy(hits.data(), out_bytes.data(), out_bytes.size());
        return hits;
    }

    static vk::GpuDevice *device_;
    static std::string skip_reason_;
};

vk::GpuDevice *VulkanRayQuery::device_ = nullptr;
std::string VulkanRayQuery::skip_reason_;

void ExpectHit(const Hit &h, float t, int primitive, const char *what) {
    EXPECT_EQ(h.hit, 1) << what;
    EXPECT_NEAR(h.t, t, 1e-5) << what;
    EXPECT_EQ(h.primitive, primitive) << what;
}

void ExpectMiss(const Hit &h, const char *what) {
    EXPECT_EQ(h.hit, 0) << what;
    EXPECT_EQ(h.t, -1.f) << what;
}

TEST_F(VulkanRayQuery, HitsTheNearestTriangleAtTheRightDistance) {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    SquareScene(0, &positions, &indices);
    device_->BuildScene(positions, indices);
    const auto spirv = vk::GpuDevice::CompileGlsl(TraceShader(64), "trace");
    const auto hits = Trace(spirv, 64,
                            {
                                {0.25f, 0.25f, 0, 0, 0, 1},   // on the diagonal: 0 or 1
                                {0.75f, 0.25f, 0, 0, 0, 1},   // below the diagonal
                                {0.25f, 0.75f, 0, 0, 0, 1},   // above it
                                {1.5f, 1.5f, 0, 0, 0, 1},     // beside everything
                                {1.5f, 0.5f, 0, 0, 0, 1},     // triangle 2 only
                                {0.9f, 0.1f, 5, 0, 0, -1},    // down: triangle 2 before the square
                                {0.9f, 0.1f, 0, 0, 0, 1},     // up: the square before triangle 2
                                {0.75f, 0.25f, 2, 0, 0, -1},  // the square's back face
                                {0.25f, 0.75f, 1.5f, 0, 0, 1},  // above the square, going up
                                {0, 0, 0, 0.5f, 0.25f, 1},      // oblique, t in direction lengths
                            });
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 1, 1e-5);
    EXPECT_TRUE(hits[0].primitive == 0 || hits[0].primitive == 1) << hits[0].primitive;
    ExpectHit(hits[1], 1, 0, "below the diagonal");
    ExpectHit(hits[2], 1, 1, "above the diagonal");
    ExpectMiss(hits[3], "beside everything");
    ExpectHit(hits[4], 3, 2, "triangle 2 only");
    ExpectHit(hits[5], 2, 2, "down through both");
    ExpectHit(hits[6], 1, 0, "up through both");
    ExpectHit(hits[7], 1, 0, "back face");
    ExpectMiss(hits[8], "above the square going up");
    ExpectHit(hits[9], 1, 0, "oblique");
}

// The integrator runs one shader for many chunks: the cached pipeline must see new buffers and
// a rebuilt scene.
TEST_F(VulkanRayQuery, RunsTheSameShaderAgainAfterARebuild) {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    SquareScene(0, &positions, &indices);
    device_->BuildScene(positions, indices);
    const auto spirv = vk::GpuDevice::CompileGlsl(TraceShader(64), "trace");
    const std::vector<Ray> rays = {{0.75f, 0.25f, 0, 0, 0, 1}, {1.5f, 0.5f, 0, 0, 0, 1}};
    auto hits = Trace(spirv, 64, rays);
    ExpectHit(hits[0], 1, 0, "first run");
    ExpectHit(hits[1], 3, 2, "first run");
    hits = Trace(spirv, 64, {rays[1], rays[0], {1.5f, 1.5f, 0, 0, 0, 1}});
    ExpectHit(hits[0], 3, 2, "second run");
    ExpectHit(hits[1], 1, 0, "second run");
    ExpectMiss(hits[2], "second run");
    SquareScene(1, &positions, &indices);
    device_->BuildScene(positions, indices);
    hits = Trace(spirv, 64, rays);
    ExpectHit(hits[0], 2, 0, "after the rebuild");
    ExpectHit(hits[1], 4, 2, "after the rebuild");
}

TEST_F(VulkanRayQuery, EmptySceneMissesEverything) {
    device_->BuildScene({}, {});
    const auto spirv = vk::GpuDevice::CompileGlsl(TraceShader(64), "trace");
    const auto hits = Trace(spirv, 64, {{0.75f, 0.25f, 0, 0, 0, 1}, {0, 0, 5, 0, 0, -1}});
    ExpectMiss(hits[0], "empty scene");
    ExpectMiss(hits[1], "empty scene");
}

// More groups than lavapipe's maxComputeWorkGroupCount[0] (65535): Run lays them out in y too.
TEST_F(VulkanRayQuery, ManyGroupsSpillIntoY) {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    SquareScene(0, &positions, &indices);
    device_->BuildScene(positions, indices);
    const auto spirv = vk::GpuDevice::CompileGlsl(TraceShader(1), "trace1");
    std::vector<Ray> rays(65535 + 1000);
    for (size_t i = 0; i < rays.size(); ++i)
        rays[i] = i % 2 ? Ray{0.75f, 0.25f, 0, 0, 0, 1} : Ray{1.5f, 0.5f, 0, 0, 0, 1};
    const auto hits = Trace(spirv, 1, rays);
    int wrong = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
        const int want = i % 2 ? 0 : 2;
        if (hits[i].hit != 1 || hits[i].primitive != want) ++wrong;
    }
    EXPECT_EQ(wrong, 0);
}

// RunStages: each stage sees what the stages before it wrote, zeroed scratch is nought at the
// start of every run (run twice: left as the first run wrote it, the second would double it),
// and the accumulators come back after the last stage. On the device DAYFLUX_VULKAN_DEVICE names
// (lavapipe by default), by our BVH's traversal: no ray queries needed.
TEST(VulkanStages, LaterStagesReadZeroedScratchThatEarlierStagesWrote) {
    std::string why;
    const char *named = std::getenv("DAYFLUX_VULKAN_DEVICE");
    auto devices =
        vk::GpuDevice::OpenAll(&why, named && *named ? named : "llvmpipe", vk::Traversal::kBvh);
    if (devices.empty()) GTEST_SKIP() << "no Vulkan device: " << why;
    vk::GpuDevice &device = *devices[0];
    const std::string head =
        "#version 460\nlayout(local_size_x = 64) in;\n"
        "layout(std430, binding = 0) buffer Scratch { uint scratch[]; };\n"
        "layout(std430, binding = 1) buffer Out { uint doubled[]; };\n"
        "void main() {\n  uint i = gl_GlobalInvocationID.x;\n  if (i >= 1000u) return;\n";
    const auto add = vk::GpuDevice::CompileGlsl(head + "  scratch[i] += i + 1u;\n}\n", "add");
    const auto twice =
        vk::GpuDevice::CompileGlsl(head + "  doubled[i] = 2u * scratch[i];\n}\n", "twice");
    for (int run = 0; run < 2; ++run) {
        std::vector<uint8_t> out(1000 * sizeof(uint32_t));
        device.RunStages(
            {{&add, 1000, 64}, {&twice, 1000, 64}},
            {vk::GpuDevice::ZeroedScratch(out.size()), vk::GpuDevice::Accumulator(&out)});
        std::vector<uint32_t> got(1000);
        std::memcpy(got.data(), out.data(), out.size());
        int wrong = 0;
        for (uint32_t i = 0; i < 1000; ++i) wrong += got[i] != 2 * (i + 1);
        EXPECT_EQ(wrong, 0) << "run " << run << " on " << device.Name() << ": entry 999 is "
                            << got[999];
    }
}

}  // namespace
}  // namespace dayflux::test
