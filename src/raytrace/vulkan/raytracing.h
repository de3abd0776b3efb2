// A Vulkan compute device for the ray tracers: with ray queries (VK_KHR_ray_query) it holds one
// scene's acceleration structures (an explicit build, then dispatches that trace against them,
// as with Embree); without them (NVIDIA's H100 and H200 have no RT cores), shaders walk a BVH
// of our own that they get as storage buffers.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace dayflux::vk {

// How shaders find hits: ray queries against the device's acceleration structures, or a walk of
// our BVH (raytrace/bvh.h); kAuto takes ray queries where the device has them.
enum class Traversal { kAuto, kRayQuery, kBvh };
// What shaderc's optimiser (spirv-opt) does before the driver compiles: -O, -Os or nothing.
enum class SpirvOptimization { kPerformance, kSize, kNone };

class GpuDevice {
  public:
    // The device choice of vulkan/devices.h (`named`, by name substring or index, else a
    // discrete GPU first, else any), among Vulkan 1.2 devices with, for float64, shaderFloat64
    // (enabled only then: shaders holding a double are invalid on a device opened without it)
    // and, for kRayQuery, VK_KHR_acceleration_structure, VK_KHR_ray_query and
    // bufferDeviceAddress. CPU devices (lavapipe) count only with allow_cpu or when named: they
    // are slower than our Embree backend. Returns nullptr and sets *why when none qualifies.
    static std::unique_ptr<GpuDevice> Open(std::string *why, bool allow_cpu = true,
                                           Traversal traversal = Traversal::kRayQuery,
                                           int ordinal = 0, const std::string &named = "",
                                           bool float64 = false);
    // Every device the choice gives (vulkan/devices.h: the ones named, else all of the best
    // kind), each opened on its own; none, with *why, when none qualifies. CPU devices only when
    // named.
    static std::vector<std::unique_ptr<GpuDevice>> OpenAll(std::string *why,
                                                           const std::string &named,
                                                           Traversal traversal,
                                                           bool float64 = false);
    // One line per Vulkan device: its index, name, type, and whether it has ray queries and
    // double precision; none, with *why, when there is no driver or device.
    static std::vector<std::string> Describe(std::string *why);
    // Whether shaders use ray queries here (else they walk a BVH: Run binds no acceleration
    // structure, and the buffers start at binding 0).
    bool RayQueries() const;
    // Whether shaders may ask that float infinities and NaNs be kept (SPIR-V's
    // SignedZeroInfNanPreserve for 32 bits): without it a compiler may fold x - x to 0 for an
    // infinite x (Mesa's NIR does).
    bool PreservesInfNan() const;
    ~GpuDevice();
    GpuDevice(const GpuDevice &) = delete;
    GpuDevice &operator=(const GpuDevice &) = delete;

    const std::string &Name() const;
    // Whether it is a CPU device (lavapipe), whose memory is the machine's.
    bool IsCpu() const;
    // The largest storage buffer a dispatch can bind (maxStorageBufferRange).
    uint64_t MaxBufferBytes() const;

    // Compiles a GLSL compute shader (source includes its #version line and
    // #extension GL_EXT_ray_query : require) to SPIR-V 1.4 for Vulkan 1.2; errors name `name`.
    // include(name) gives the text of a file the source #includes ("name").
    static std::vector<uint32_t> CompileGlsl(
        const std::string &source, const std::string &name,
        const std::function<std::string(const std::string &)> &include = {},
        SpirvOptimization optimization = SpirvOptimization::kPerformance);

    // Builds (or rebuilds) one bottom-level structure with all triangles (positions: xyz floats
    // per vertex; indices: 3 per triangle) flagged OPAQUE and not culled, and a top-level
    // structure with one identity instance. Triangle i is primitive index i in the shader
    // (rayQueryGetIntersectionPrimitiveIndexEXT). With no triangles, rays miss everything.
    // boxes (6 floats each: min xyz, max xyz) are procedural: a second instance, custom index 1,
    // whose candidates the shader intersects itself (box i is primitive index i there); the
    // triangles' instance has custom index 0.
    void BuildScene(const std::vector<float> &positions, const std::vector<uint32_t> &indices,
                    const std::vector<float> &boxes = {});

    // Data that stays on the device between runs (a scene's tables): copied once into
    // device-local memory, where shaders read it fastest on a discrete GPU. Returns its handle.
    int Resident(const std::vector<uint8_t> &data);
    // A buffer as Run binds it: a host vector copied in before the run and, with read_back, out
    // after it (host-visible memory, which the shader reads across the bus on a discrete GPU);
    // an accumulator, a host vector's size of zeros in device memory that the shader adds to,
    // copied into the vector after the run; a resident buffer; or scratch, `scratch` bytes on
    // the device that the shader alone reads and writes (their contents undefined at the start).
    // Zeroed scratch: `scratch` bytes of zeros on the device, for a later stage of the same
    // run to read (RunStages).
    struct Binding {
        std::vector<uint8_t> *host = nullptr;
        bool read_back = true;
        int resident = -1;
        uint64_t scratch = 0;
        bool accumulator = false;
        bool zeroed = false;
    };
    static Binding In(std::vector<uint8_t> *host) { return {host, false, -1, 0, false, false}; }
    static Binding InOut(std::vector<uint8_t> *host) { return {host, true, -1, 0, false, false}; }
    static Binding Accumulator(std::vector<uint8_t> *host) {
        return {host, true, -1, 0, true, false};
    }
    static Binding OnDevice(int handle) { return {nullptr, false, handle, 0, false, false}; }
    static Binding Scratch(uint64_t bytes) { return {nullptr, false, -1, bytes, false, false}; }
    static Binding ZeroedScratch(uint64_t bytes) {
        return {nullptr, false, -1, bytes, false, true};
    }
    // The scratch one run may bind in all: a quarter of the device's local memory, at most
    // 2 GiB (a CPU device's, such as lavapipe's, 256 MiB: it is the machine's memory).
    uint64_t ScratchBudget() const;
    // The ArrayStride of the runtime array that is the first member of the storage block at set
    // 0, `binding` in spirv (the std430 size of its element as the compiler laid it out); 0
    // where there is none.
    static uint32_t RuntimeArrayStride(const std::vector<uint32_t> &spirv, uint32_t binding);
    // Calls visit(opcode, the instruction's words, their count) for each instruction of spirv
    // after its header, in order, until visit returns false; false where spirv is malformed (an
    // instruction of no words, or one running past the end).
    using SpirvVisitor = std::function<bool(uint32_t op, const uint32_t *words, uint32_t count)>;
    static bool ForEachInstruction(const std::vector<uint32_t> &spirv, const SpirvVisitor &visit);
    // Whether spirv declares the Float64 capability or a 64-bit float type: what a device
    // without shaderFloat64 (Apple's, Intel's) cannot run.
    static bool UsesFloat64(const std::vector<uint32_t> &spirv);
    // Runs spirv over `invocations` invocations in groups of local_size_x (which must match the
    // shader's), with the top-level structure at set 0 binding 0 (accelerationStructureEXT) and
    // storage buffers at bindings 1, 2, ... in the order given (without ray queries: no
    // structure, buffers at 0, 1, ...). Push constants: one uint, the stage's phase (RunStages).
    // When the groups needed exceed maxComputeWorkGroupCount[0] (65535 on lavapipe) they are laid
    // out in y as well, so a shader that may see that many should index with
    // gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x
    // (y is 0 otherwise). Every shader must ignore indices
    // >= invocations. Pipelines are cached by code, so running the same spirv again is cheap.
    void Run(const std::vector<uint32_t> &spirv, uint32_t invocations, uint32_t local_size_x,
             const std::vector<Binding> &bindings);
    // Several shaders, one after the other in one submission over the same bindings (each
    // stage sees what the stages before it wrote), the accumulators copied back after the last.
    // phase: a push constant (`layout(push_constant) uniform ... { uint phase; }`), so that one
    // shader, one pipeline, may run as several stages.
    struct Stage {
        const std::vector<uint32_t> *spirv;
        uint32_t invocations, local_size_x;
        uint32_t phase = 0;
    };
    void RunStages(const std::vector<Stage> &stages, const std::vector<Binding> &bindings);
    // The device's time for each stage (with invocations) of the last Run or RunStages, from
    // timestamp queries: the first from its start, each other from the end of the one before
    // (the barrier between them included). Empty where the queue has no timestamps.
    const std::vector<double> &LastStageSeconds() const;

    struct Impl;

  private:
    explicit GpuDevice(std::unique_ptr<Impl> impl);
    static std::unique_ptr<GpuDevice> FinishOpen(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace dayflux::vk
