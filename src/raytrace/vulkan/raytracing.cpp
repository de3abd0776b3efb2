#include "raytrace/vulkan/raytracing.h"

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <shaderc/shaderc.hpp>
#include <string_view>
#include <unordered_map>

#include "raytrace/vulkan/devices.h"
#include "util/errors.h"

namespace dayflux::vk {

namespace {

// The results a run meets in practice, by name; the rest by number.
std::string ResultName(VkResult r) {
    switch (r) {
        case VK_ERROR_OUT_OF_HOST_MEMORY:
            return "VK_ERROR_OUT_OF_HOST_MEMORY";
        case VK_ERROR_OUT_OF_DEVICE_MEMORY:
            return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
        case VK_ERROR_INITIALIZATION_FAILED:
            return "VK_ERROR_INITIALIZATION_FAILED";
        case VK_ERROR_DEVICE_LOST:
            return "VK_ERROR_DEVICE_LOST: the GPU stopped or was reset";
        case VK_ERROR_UNKNOWN:
            return "VK_ERROR_UNKNOWN";
        case VK_TIMEOUT:
            return "VK_TIMEOUT";
        default:
            return std::to_string(r);
    }
}

// Every Vulkan call is checked; a failure is an error with the call and its result named (a run
// that has written records keeps them for -r: rcontrib/run.cpp).
#define VK_CHECK(call)                                                \
    do {                                                              \
        VkResult vk_check_result = (call);                            \
        if (vk_check_result != VK_SUCCESS)                            \
            ErrorExit(std::string("Vulkan: ") + #call + " failed (" + \
                      ResultName(vk_check_result) + ")");             \
    } while (false)

const char *const kRequiredExtensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                           VK_KHR_RAY_QUERY_EXTENSION_NAME};
// VK_KHR_acceleration_structure depends on deferred host operations; buffer device address is
// core in 1.2, so both are enabled when listed but not demanded.
const char *const kOptionalExtensions[] = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
                                           VK_KHR_BUFFER_DEVICE_ADDRESS_EXTENSION_NAME};

VkDeviceSize AlignUp(VkDeviceSize x, VkDeviceSize a) { return (x + a - 1) / a * a; }

// The feature structures queried and enabled, chained as Vulkan wants them.
struct FeatureChain {
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    VkPhysicalDeviceRayQueryFeaturesKHR rq{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};

    FeatureChain() {
        f2.pNext = &v12;
        v12.pNext = &as;
        as.pNext = &rq;
    }
    FeatureChain(const FeatureChain &) = delete;
};

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void *mapped = nullptr;       // host-visible buffers stay mapped for their lifetime
    VkDeviceAddress address = 0;  // when created with SHADER_DEVICE_ADDRESS usage
};

struct Pipeline {
    std::vector<uint32_t> code;  // to tell hash collisions apart
    uint32_t buffer_count = 0;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

}  // namespace

struct GpuDevice::Impl {
    bool ray_queries = false;
    bool preserves_inf_nan = false;  // shaderSignedZeroInfNanPreserveFloat32
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t queue_family = 0;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    std::string name;
    VkPhysicalDeviceLimits limits{};
    VkPhysicalDeviceAccelerationStructurePropertiesKHR as_props{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};

    PFN_vkGetAccelerationStructureBuildSizesKHR GetBuildSizes = nullptr;
    PFN_vkCreateAccelerationStructureKHR CreateAccelerationStructure = nullptr;
    PFN_vkDestroyAccelerationStructureKHR DestroyAccelerationStructure = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR CmdBuildAccelerationStructures = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR GetAccelerationStructureAddress = nullptr;

    // The scene: bottom level (absent when empty) and top level with its storage.
    VkAccelerationStructureKHR blas = VK_NULL_HANDLE, tlas = VK_NULL_HANDLE;
    VkAccelerationStructureKHR box_blas = VK_NULL_HANDLE;  // procedural boxes (analytic shapes)
    Buffer blas_storage, tlas_storage, box_storage;

    std::unordered_map<size_t, Pipeline> pipelines;
    std::vector<Buffer> run_buffers;       // grown as needed, reused across runs
    std::vector<Buffer> scratch_buffers;   // likewise, device-local
    std::vector<Buffer> accum_buffers;     // likewise, device-local (Binding::accumulator)
    std::vector<Buffer> readback_buffers;  // their host-visible copies
    std::vector<Buffer> resident;          // Resident(): device-local, with the data's own sizes
    std::vector<VkDeviceSize> resident_size;
    // Timestamps around RunStages' stages, where the queue has them (timestamp_bits > 0).
    VkQueryPool timestamps = VK_NULL_HANDLE;
    uint32_t timestamp_slots = 0, timestamp_bits = 0;
    std::vector<double> stage_seconds;  // the last RunStages'

    ~Impl() {
        if (device) {
            vkDeviceWaitIdle(device);
            if (timestamps) vkDestroyQueryPool(device, timestamps, nullptr);
            DestroyScene();
            for (auto &[key, p] : pipelines) DestroyPipeline(p);
            for (Buffer &b : run_buffers) Destroy(b);
            for (Buffer &b : scratch_buffers) Destroy(b);
            for (Buffer &b : accum_buffers) Destroy(b);
            for (Buffer &b : readback_buffers) Destroy(b);
            for (Buffer &b : resident) Destroy(b);
            if (fence) vkDestroyFence(device, fence, nullptr);
            if (pool) vkDestroyCommandPool(device, pool, nullptr);
            vkDestroyDevice(device, nullptr);
        }
        if (instance) vkDestroyInstance(instance, nullptr);
    }

    uint32_t MemoryType(uint32_t bits, VkMemoryPropertyFlags flags) const {
        VkPhysicalDeviceMemoryProperties mp;
        vkGetPhysicalDeviceMemoryProperties(physical, &mp);
        for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & flags) == flags) return i;
        return UINT32_MAX;
    }

    // Host buffers are mapped and coherent; the others (structures, scratch) are never touched
    // by the host, so they go in device-local memory where there is some (on a discrete GPU,
    // tracing through host memory would cross the bus).
    // read_back: a host buffer the CPU reads, in cached memory where there is some (write-
    // combined memory reads slowly, and accumulators are up to a GiB).
    Buffer Create(VkDeviceSize size, VkBufferUsageFlags usage, bool host, bool read_back = false) {
        Buffer b;
        b.size = std::max<VkDeviceSize>(size, 16);
        VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bci.size = b.size;
        bci.usage = usage;
        VK_CHECK(vkCreateBuffer(device, &bci, nullptr, &b.buffer));
        VkMemoryRequirements mr;
        vkGetBufferMemoryRequirements(device, b.buffer, &mr);
        VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) mai.pNext = &flags;
        mai.allocationSize = mr.size;
        const VkMemoryPropertyFlags host_flags =
            VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        mai.memoryTypeIndex =
            host ? MemoryType(mr.memoryTypeBits,
                              host_flags | (read_back ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0))
                 : MemoryType(mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (host && read_back && mai.memoryTypeIndex == UINT32_MAX)
            mai.memoryTypeIndex = MemoryType(mr.memoryTypeBits, host_flags);
        if (!host && mai.memoryTypeIndex == UINT32_MAX)
            mai.memoryTypeIndex = MemoryType(mr.memoryTypeBits, 0);
        if (mai.memoryTypeIndex == UINT32_MAX)
            ErrorExit(std::string("Vulkan: no ") + (host ? "host-visible " : "") +
                      "memory type for a buffer on " + name);
        VK_CHECK(vkAllocateMemory(device, &mai, nullptr, &b.memory));
        VK_CHECK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
        if (host) VK_CHECK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
        if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
            VkBufferDeviceAddressInfo bdai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
            bdai.buffer = b.buffer;
            b.address = vkGetBufferDeviceAddress(device, &bdai);
        }
        return b;
    }

    void Destroy(Buffer &b) {
        if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
        if (b.memory) vkFreeMemory(device, b.memory, nullptr);  // unmaps too
        b = Buffer{};
    }

    void DestroyPipeline(Pipeline &p) {
        vkDestroyPipeline(device, p.pipeline, nullptr);
        vkDestroyShaderModule(device, p.module, nullptr);
        vkDestroyPipelineLayout(device, p.layout, nullptr);
        vkDestroyDescriptorSetLayout(device, p.set_layout, nullptr);
    }

    void DestroyScene() {
        if (tlas) DestroyAccelerationStructure(device, tlas, nullptr);
        if (blas) DestroyAccelerationStructure(device, blas, nullptr);
        if (box_blas) DestroyAccelerationStructure(device, box_blas, nullptr);
        tlas = blas = box_blas = VK_NULL_HANDLE;
        Destroy(tlas_storage);
        Destroy(blas_storage);
        Destroy(box_storage);
    }

    VkCommandBuffer BeginCommands() {
        VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        cbai.commandPool = pool;
        cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cbai.commandBufferCount = 1;
        VkCommandBuffer cb;
        VK_CHECK(vkAllocateCommandBuffers(device, &cbai, &cb));
        VkCommandBufferBeginInfo cbbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK_CHECK(vkBeginCommandBuffer(cb, &cbbi));
        return cb;
    }

    // Ends, submits and waits for cb, then frees it.
    void SubmitAndWait(VkCommandBuffer cb) {
        VK_CHECK(vkEndCommandBuffer(cb));
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cb;
        VK_CHECK(vkQueueSubmit(queue, 1, &si, fence));
        VK_CHECK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
        VK_CHECK(vkResetFences(device, 1, &fence));
        vkFreeCommandBuffers(device, pool, 1, &cb);
    }

    // Creates an acceleration structure of `type` for `build` (geometry filled in), records its
    // build into cb with a new scratch buffer that the caller frees after the submission.
    VkAccelerationStructureKHR RecordBuild(VkCommandBuffer cb, VkAccelerationStructureTypeKHR type,
                                           VkAccelerationStructureBuildGeometryInfoKHR &build,
                                           uint32_t primitive_count, Buffer *storage,
                                           Buffer *scratch) {
        VkAccelerationStructureBuildSizesInfoKHR sizes{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
        GetBuildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &build,
                      &primitive_count, &sizes);
        *storage = Create(sizes.accelerationStructureSize,
                          VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                              VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                          false);
        const VkDeviceSize align =
            std::max<VkDeviceSize>(as_props.minAccelerationStructureScratchOffsetAlignment, 1);
        *scratch = Create(
            sizes.buildScratchSize + align,
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, false);
        VkAccelerationStructureCreateInfoKHR asci{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
        asci.buffer = storage->buffer;
        asci.size = storage->size;
        asci.type = type;
        VkAccelerationStructureKHR as;
        VK_CHECK(CreateAccelerationStructure(device, &asci, nullptr, &as));
        build.dstAccelerationStructure = as;
        build.scratchData.deviceAddress = AlignUp(scratch->address, align);
        VkAccelerationStructureBuildRangeInfoKHR range{};
        range.primitiveCount = primitive_count;
        const VkAccelerationStructureBuildRangeInfoKHR *ranges = &range;
        CmdBuildAccelerationStructures(cb, 1, &build, &ranges);
        return as;
    }
};

GpuDevice::GpuDevice(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GpuDevice::~GpuDevice() = default;
const std::string &GpuDevice::Name() const { return impl_->name; }
uint64_t GpuDevice::MaxBufferBytes() const { return impl_->limits.maxStorageBufferRange; }
const std::vector<double> &GpuDevice::LastStageSeconds() const { return impl_->stage_seconds; }

bool GpuDevice::IsCpu() const {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(impl_->physical, &p);
    return p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}

uint64_t GpuDevice::ScratchBudget() const {
    if (IsCpu()) return uint64_t{256} << 20;
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(impl_->physical, &mp);
    uint64_t local = 0;
    for (uint32_t i = 0; i < mp.memoryHeapCount; ++i)
        if (mp.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            local = std::max<uint64_t>(local, mp.memoryHeaps[i].size);
    return std::clamp<uint64_t>(local / 4, uint64_t{64} << 20, uint64_t{2} << 30);
}

uint32_t GpuDevice::RuntimeArrayStride(const std::vector<uint32_t> &spirv, uint32_t binding) {
    // SPIR-V opcodes and decorations (the SPIR-V specification, 3.32 and 3.20).
    constexpr uint32_t kOpTypeRuntimeArray = 29, kOpTypeStruct = 30, kOpTypePointer = 32,
                       kOpVariable = 59, kOpDecorate = 71, kDecorationArrayStride = 6,
                       kDecorationBinding = 33, kDecorationDescriptorSet = 34;
    std::unordered_map<uint32_t, uint32_t> stride, binding_of, set_of, pointee, first_member,
        variable_type;
    std::unordered_map<uint32_t, bool> runtime_array;
    ForEachInstruction(spirv, [&](uint32_t op, const uint32_t *w, uint32_t words) {
        if (op == kOpDecorate && words >= 4) {
            if (w[2] == kDecorationArrayStride) stride[w[1]] = w[3];
            if (w[2] == kDecorationBinding) binding_of[w[1]] = w[3];
            if (w[2] == kDecorationDescriptorSet) set_of[w[1]] = w[3];
        } else if (op == kOpTypeRuntimeArray && words >= 3) {
            runtime_array[w[1]] = true;
        } else if (op == kOpTypeStruct && words >= 3) {
            first_member[w[1]] = w[2];
        } else if (op == kOpTypePointer && words >= 4) {
            pointee[w[1]] = w[3];
        } else if (op == kOpVariable && words >= 3) {
            variable_type[w[2]] = w[1];
        }
        return true;  // (malformed: what was read before, which finds nothing it should not)
    });
    for (const auto &[var, b] : binding_of) {
        if (b != binding || set_of[var] != 0 || !variable_type.count(var)) continue;
        const uint32_t block = pointee[variable_type[var]];
        if (!first_member.count(block)) continue;
        const uint32_t array = first_member[block];
        if (runtime_array[array] && stride.count(array)) return stride[array];
    }
    return 0;
}

bool GpuDevice::UsesFloat64(const std::vector<uint32_t> &spirv) {
    // (the SPIR-V specification, 3.31 and 3.32: OpCapability Float64, OpTypeFloat 64)
    constexpr uint32_t kOpCapability = 17, kCapabilityFloat64 = 10, kOpTypeFloat = 22;
    bool found = false;
    const bool whole = ForEachInstruction(spirv, [&](uint32_t op, const uint32_t *w, uint32_t n) {
        found = (op == kOpCapability && n >= 2 && w[1] == kCapabilityFloat64) ||
                (op == kOpTypeFloat && n >= 3 && w[2] == 64);
        return !found;
    });
    return found || !whole;  // (malformed: assume the worst)
}

bool GpuDevice::ForEachInstruction(const std::vector<uint32_t> &spirv, const SpirvVisitor &visit) {
    for (size_t i = 5; i < spirv.size();) {
        const uint32_t op = spirv[i] & 0xffffu, words = spirv[i] >> 16;
        if (words == 0 || i + words > spirv.size()) return false;
        if (!visit(op, &spirv[i], words)) return true;
        i += words;
    }
    return true;
}

namespace {

// What a device lacks for ray queries ("" if nothing).
std::string LacksRayQueries(VkPhysicalDevice device) {
    uint32_t ne = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &ne, nullptr);
    std::vector<VkExtensionProperties> ext(ne);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &ne, ext.data());
    std::string lacks;
    for (const char *e : kRequiredExtensions)
        if (std::none_of(ext.begin(), ext.end(), [&](const VkExtensionProperties &x) {
                return std::strcmp(x.extensionName, e) == 0;
            }))
            lacks += std::string(" ") + e;
    if (lacks.empty()) {
        FeatureChain f;
        vkGetPhysicalDeviceFeatures2(device, &f.f2);
        if (!f.v12.bufferDeviceAddress) lacks += " bufferDeviceAddress";
        if (!f.as.accelerationStructure) lacks += " accelerationStructure";
        if (!f.rq.rayQuery) lacks += " rayQuery";
    }
    return lacks;
}

}  // namespace

std::vector<std::string> GpuDevice::Describe(std::string *why) {
    VkInstance instance = CreateInstance(why);
    if (!instance) return {};
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    std::vector<std::string> lines;
    for (uint32_t i = 0; i < n; ++i) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        VkPhysicalDeviceFeatures f;
        vkGetPhysicalDeviceFeatures(devices[i], &f);
        const char *type = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? "discrete GPU"
                           : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU
                               ? "integrated GPU"
                           : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? "CPU"
                                                                         : "other";
        const std::string rq = LacksRayQueries(devices[i]);
        lines.push_back(std::to_string(i) + ": " + p.deviceName + " (" + type + ", Vulkan " +
                        std::to_string(VK_API_VERSION_MAJOR(p.apiVersion)) + "." +
                        std::to_string(VK_API_VERSION_MINOR(p.apiVersion)) + "): ray queries " +
                        (rq.empty() ? "yes" : "no (lacks" + rq + ")") + ", float64 " +
                        (f.shaderFloat64 ? "yes" : "no"));
    }
    vkDestroyInstance(instance, nullptr);
    if (lines.empty()) *why = "no Vulkan device";
    return lines;
}

std::vector<std::unique_ptr<GpuDevice>> GpuDevice::OpenAll(std::string *why,
                                                           const std::string &named,
                                                           Traversal traversal, bool float64) {
    std::vector<std::unique_ptr<GpuDevice>> all;
    for (int k = 0;; ++k) {
        std::string why_k;
        std::unique_ptr<GpuDevice> d = Open(&why_k, !named.empty(), traversal, k, named, float64);
        if (!d) {
            if (all.empty()) *why = why_k;
            return all;
        }
        all.push_back(std::move(d));
    }
}

std::unique_ptr<GpuDevice> GpuDevice::Open(std::string *why, bool allow_cpu, Traversal traversal,
                                           int ordinal, const std::string &named, bool float64) {
    auto impl = std::make_unique<Impl>();
    impl->instance = CreateInstance(why);
    if (!impl->instance) return nullptr;
    const auto lacks = [traversal, float64](VkPhysicalDevice device) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(device, &p);
        if (p.apiVersion < VK_API_VERSION_1_2) return std::string(" Vulkan 1.2");
        VkPhysicalDeviceFeatures f;
        vkGetPhysicalDeviceFeatures(device, &f);
        std::string lacks = !float64 || f.shaderFloat64 ? "" : " shaderFloat64";
        if (traversal == Traversal::kRayQuery) lacks += LacksRayQueries(device);
        return lacks;
    };
    const std::vector<VkPhysicalDevice> choice =
        ChooseDevices(impl->instance, lacks, allow_cpu, named,
                      traversal == Traversal::kRayQuery
                          ? (float64 ? "with ray queries and double precision" : "with ray queries")
                      : float64 ? "with double precision"
                                : "for compute",
                      why);
    if (ordinal >= static_cast<int>(choice.size())) {
        if (!choice.empty()) *why = "no more devices";
        return nullptr;
    }
    impl->physical = choice[ordinal];
    impl->ray_queries = traversal != Traversal::kBvh && LacksRayQueries(impl->physical).empty();
    VkPhysicalDeviceVulkan12Properties props12{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &props12;
    if (impl->ray_queries) props12.pNext = &impl->as_props;
    vkGetPhysicalDeviceProperties2(impl->physical, &props);
    impl->as_props.pNext = nullptr;
    impl->preserves_inf_nan = props12.shaderSignedZeroInfNanPreserveFloat32 == VK_TRUE;
    impl->name = props.properties.deviceName;
    impl->limits = props.properties.limits;
    if (!ComputeQueueFamily(impl->physical, &impl->queue_family)) {
        *why = impl->name + " has no compute queue";
        return nullptr;
    }
    {
        uint32_t n = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(impl->physical, &n, nullptr);
        std::vector<VkQueueFamilyProperties> families(n);
        vkGetPhysicalDeviceQueueFamilyProperties(impl->physical, &n, families.data());
        impl->timestamp_bits = families[impl->queue_family].timestampValidBits;
    }
    const float priority = 1.f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = impl->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;

    VkPhysicalDeviceFeatures available;
    vkGetPhysicalDeviceFeatures(impl->physical, &available);
    FeatureChain enable;
    enable.f2.features.shaderFloat64 = float64 ? VK_TRUE : VK_FALSE;
    enable.f2.features.shaderInt64 = available.shaderInt64;
    std::vector<const char *> extensions;
    if (impl->ray_queries) {
        enable.v12.bufferDeviceAddress = VK_TRUE;
        enable.as.accelerationStructure = VK_TRUE;
        enable.rq.rayQuery = VK_TRUE;
        uint32_t ne = 0;
        vkEnumerateDeviceExtensionProperties(impl->physical, nullptr, &ne, nullptr);
        std::vector<VkExtensionProperties> ext(ne);
        vkEnumerateDeviceExtensionProperties(impl->physical, nullptr, &ne, ext.data());
        extensions.assign(std::begin(kRequiredExtensions), std::end(kRequiredExtensions));
        for (const char *e : kOptionalExtensions)
            for (const auto &x : ext)
                if (std::strcmp(x.extensionName, e) == 0) extensions.push_back(e);
    } else {
        enable.v12.pNext = nullptr;  // no acceleration-structure or ray-query features
    }

    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &enable.f2;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
    VK_CHECK(vkCreateDevice(impl->physical, &dci, nullptr, &impl->device));
    vkGetDeviceQueue(impl->device, impl->queue_family, 0, &impl->queue);

    // Extension entry points are not exported by the loader; fetch them from the device.
    auto load = [&](const char *fn) {
        PFN_vkVoidFunction f = vkGetDeviceProcAddr(impl->device, fn);
        if (!f) ErrorExit(std::string("Vulkan: ") + impl->name + " does not provide " + fn);
        return f;
    };
    if (!impl->ray_queries) return FinishOpen(std::move(impl));
    impl->GetBuildSizes = reinterpret_cast<PFN_vkGetAccelerationStructureBuildSizesKHR>(
        load("vkGetAccelerationStructureBuildSizesKHR"));
    impl->CreateAccelerationStructure = reinterpret_cast<PFN_vkCreateAccelerationStructureKHR>(
        load("vkCreateAccelerationStructureKHR"));
    impl->DestroyAccelerationStructure = reinterpret_cast<PFN_vkDestroyAccelerationStructureKHR>(
        load("vkDestroyAccelerationStructureKHR"));
    impl->CmdBuildAccelerationStructures =
        reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresKHR>(
            load("vkCmdBuildAccelerationStructuresKHR"));
    impl->GetAccelerationStructureAddress =
        reinterpret_cast<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
            load("vkGetAccelerationStructureDeviceAddressKHR"));

    return FinishOpen(std::move(impl));
}

std::unique_ptr<GpuDevice> GpuDevice::FinishOpen(std::unique_ptr<Impl> impl) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = impl->queue_family;
    VK_CHECK(vkCreateCommandPool(impl->device, &pci, nullptr, &impl->pool));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(impl->device, &fci, nullptr, &impl->fence));
    return std::unique_ptr<GpuDevice>(new GpuDevice(std::move(impl)));
}

bool GpuDevice::RayQueries() const { return impl_->ray_queries; }
bool GpuDevice::PreservesInfNan() const { return impl_->preserves_inf_nan; }

namespace {

// shaderc's includer over a function giving files' texts (#include "name").
class Includer : public shaderc::CompileOptions::IncluderInterface {
  public:
    explicit Includer(std::function<std::string(const std::string &)> include)
        : include_(std::move(include)) {}
    shaderc_include_result *GetInclude(const char *requested, shaderc_include_type, const char *,
                                       size_t) override {
        auto *file = new File{requested, include_(requested), {}};
        file->result = {file->name.c_str(), file->name.size(), file->text.c_str(),
                        file->text.size(), file};
        return &file->result;
    }
    void ReleaseInclude(shaderc_include_result *result) override {
        delete static_cast<File *>(result->user_data);
    }

  private:
    struct File {
        std::string name, text;
        shaderc_include_result result;
    };
    std::function<std::string(const std::string &)> include_;
};

}  // namespace

std::vector<uint32_t> GpuDevice::CompileGlsl(
    const std::string &source, const std::string &name,
    const std::function<std::string(const std::string &)> &include,
    SpirvOptimization optimization) {
    shaderc::Compiler compiler;
    shaderc::CompileOptions options;
    if (include) options.SetIncluder(std::make_unique<Includer>(include));
    options.SetOptimizationLevel(
        optimization == SpirvOptimization::kPerformance ? shaderc_optimization_level_performance
        : optimization == SpirvOptimization::kSize      ? shaderc_optimization_level_size
                                                        : shaderc_optimization_level_zero);
    options.SetTargetEnvironment(shaderc_target_env_vulkan, shaderc_env_version_vulkan_1_2);
    // Ray queries need SPIR-V 1.4 (SPV_KHR_ray_query), which Vulkan 1.2 accepts.
    options.SetTargetSpirv(shaderc_spirv_version_1_4);
    auto result = compiler.CompileGlslToSpv(source, shaderc_compute_shader, name.c_str(), options);
    if (result.GetCompilationStatus() != shaderc_compilation_status_success)
        ErrorExit("GLSL compilation of " + name + " failed:\n" + result.GetErrorMessage());
    return {result.cbegin(), result.cend()};
}

void GpuDevice::BuildScene(const std::vector<float> &positions,
                           const std::vector<uint32_t> &indices, const std::vector<float> &boxes) {
    Impl &d = *impl_;
    CHECK(d.ray_queries);  // without them, shaders get their BVH as buffers
    CHECK(positions.size() % 3 == 0);
    CHECK(indices.size() % 3 == 0);
    const size_t vertex_count = positions.size() / 3;
    for (uint32_t i : indices) CHECK(i < vertex_count);
    const size_t triangle_count = indices.size() / 3;
    CHECK(boxes.size() % 6 == 0);
    const size_t box_count = boxes.size() / 6;
    if (triangle_count > d.as_props.maxPrimitiveCount)
        ErrorExit("scene has " + std::to_string(triangle_count) + " triangles; " + d.name +
                  " takes at most " + std::to_string(d.as_props.maxPrimitiveCount) +
                  " in one structure");

    // A structure may be in use by an earlier run until the device is idle.
    VK_CHECK(vkDeviceWaitIdle(d.device));
    d.DestroyScene();

    constexpr VkBufferUsageFlags kInput =
        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
        VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    // Inputs and scratch are only needed during the builds and freed after them.
    Buffer vertices, triangles, aabbs, instances, blas_scratch, box_scratch, tlas_scratch;
    VkCommandBuffer cb = d.BeginCommands();

    // A bottom-level structure of one geometry (triangles or boxes), recorded into cb.
    const auto build_bottom = [&](const VkAccelerationStructureGeometryKHR &geometry, size_t count,
                                  Buffer *storage, Buffer *scratch) {
        VkAccelerationStructureBuildGeometryInfoKHR build{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
        build.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
        build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
        build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
        build.geometryCount = 1;
        build.pGeometries = &geometry;
        return d.RecordBuild(cb, build.type, build, static_cast<uint32_t>(count), storage, scratch);
    };
    std::vector<VkAccelerationStructureInstanceKHR> instance_list;
    const float identity[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
    // One instance per bottom level: custom index 0 for the triangles, 1 for the boxes.
    const auto add_instance = [&](VkAccelerationStructureKHR blas, uint32_t custom) {
        VkAccelerationStructureInstanceKHR instance{};
        VkAccelerationStructureDeviceAddressInfoKHR asdai{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
        asdai.accelerationStructure = blas;
        std::memcpy(instance.transform.matrix, identity, sizeof identity);
        instance.instanceCustomIndex = custom;
        instance.mask = 0xff;
        // Both sides of every surface are hit; materials decide what a back face means.
        instance.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
        instance.accelerationStructureReference =
            d.GetAccelerationStructureAddress(d.device, &asdai);
        instance_list.push_back(instance);
    };
    if (triangle_count > 0) {
        vertices = d.Create(positions.size() * sizeof(float), kInput, true);
        std::memcpy(vertices.mapped, positions.data(), positions.size() * sizeof(float));
        triangles = d.Create(indices.size() * sizeof(uint32_t), kInput, true);
        std::memcpy(triangles.mapped, indices.data(), indices.size() * sizeof(uint32_t));

        VkAccelerationStructureGeometryKHR geometry{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
        geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
        geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        auto &tri = geometry.geometry.triangles;
        tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
        tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        tri.vertexData.deviceAddress = vertices.address;
        tri.vertexStride = 3 * sizeof(float);
        tri.maxVertex = static_cast<uint32_t>(vertex_count - 1);
        tri.indexType = VK_INDEX_TYPE_UINT32;
        tri.indexData.deviceAddress = triangles.address;
        d.blas = build_bottom(geometry, triangle_count, &d.blas_storage, &blas_scratch);

        add_instance(d.blas, 0);
    }
    if (box_count > 0) {
        aabbs = d.Create(boxes.size() * sizeof(float), kInput, true);
        std::memcpy(aabbs.mapped, boxes.data(), boxes.size() * sizeof(float));
        VkAccelerationStructureGeometryKHR geometry{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
        geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
        geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        auto &box = geometry.geometry.aabbs;
        box.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
        box.data.deviceAddress = aabbs.address;
        box.stride = sizeof(VkAabbPositionsKHR);
        d.box_blas = build_bottom(geometry, box_count, &d.box_storage, &box_scratch);
        add_instance(d.box_blas, 1);
    }
    if (!instance_list.empty()) {
        // The top-level build reads the bottom levels.
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
        barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                             VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier,
                             0, nullptr, 0, nullptr);
    }

    // An empty scene is a top level with no instances, which every ray misses.
    const uint32_t instance_count = static_cast<uint32_t>(instance_list.size());
    const size_t instance_bytes =
        std::max<size_t>(1, instance_list.size()) * sizeof(VkAccelerationStructureInstanceKHR);
    instances = d.Create(instance_bytes, kInput, true);
    CHECK(instances.address % 16 == 0);  // required of instance data
    if (!instance_list.empty())
        std::memcpy(instances.mapped, instance_list.data(),
                    instance_list.size() * sizeof(VkAccelerationStructureInstanceKHR));
    VkAccelerationStructureGeometryKHR geometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.geometry.instances.sType =
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    geometry.geometry.instances.data.deviceAddress = instances.address;
    VkAccelerationStructureBuildGeometryInfoKHR build{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    build.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    build.geometryCount = 1;
    build.pGeometries = &geometry;
    d.tlas = d.RecordBuild(cb, build.type, build, instance_count, &d.tlas_storage, &tlas_scratch);
    d.SubmitAndWait(cb);

    for (Buffer *b :
         {&vertices, &triangles, &aabbs, &instances, &blas_scratch, &box_scratch, &tlas_scratch})
        d.Destroy(*b);
}

int GpuDevice::Resident(const std::vector<uint8_t> &data) {
    Impl &d = *impl_;
    if (data.size() > d.limits.maxStorageBufferRange)
        ErrorExit("Vulkan: a buffer of " + std::to_string(data.size()) + " bytes exceeds " +
                  d.name + "'s maxStorageBufferRange of " +
                  std::to_string(d.limits.maxStorageBufferRange));
    Buffer b = d.Create(
        data.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
    if (!data.empty()) {
        Buffer staging = d.Create(data.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
        std::memcpy(staging.mapped, data.data(), data.size());
        VkCommandBuffer cb = d.BeginCommands();
        VkBufferCopy region{0, 0, data.size()};
        vkCmdCopyBuffer(cb, staging.buffer, b.buffer, 1, &region);
        // Later dispatches read what the copy wrote.
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0,
                             nullptr);
        d.SubmitAndWait(cb);
        d.Destroy(staging);
    }
    d.resident.push_back(b);
    d.resident_size.push_back(data.size());
    return static_cast<int>(d.resident.size()) - 1;
}

void GpuDevice::Run(const std::vector<uint32_t> &spirv, uint32_t invocations, uint32_t local_size_x,
                    const std::vector<Binding> &bindings) {
    RunStages({{&spirv, invocations, local_size_x}}, bindings);
}

// The pipeline cache's key for spirv with nb storage buffers.
static size_t PipelineKey(const std::vector<uint32_t> &spirv, uint32_t nb) {
    size_t key = std::hash<std::string_view>{}(std::string_view(
        reinterpret_cast<const char *>(spirv.data()), spirv.size() * sizeof(uint32_t)));
    return key ^ (nb + 0x9e3779b97f4a7c15ull + (key << 6) + (key >> 2));
}

// The compute pipeline of spirv with nb storage buffers (after the structure, with ray
// queries), from the cache when this code ran before.
static const Pipeline &PipelineFor(GpuDevice::Impl &d, const std::vector<uint32_t> &spirv,
                                   uint32_t nb) {
    VkDevice dev = d.device;
    const uint32_t first = d.ray_queries ? 1 : 0;
    const size_t key = PipelineKey(spirv, nb);
    auto it = d.pipelines.find(key);
    if (it != d.pipelines.end() && (it->second.code != spirv || it->second.buffer_count != nb)) {
        VK_CHECK(vkDeviceWaitIdle(dev));
        d.DestroyPipeline(it->second);
        d.pipelines.erase(it);
        it = d.pipelines.end();
    }
    if (it == d.pipelines.end()) {
        Pipeline p;
        p.code = spirv;
        p.buffer_count = nb;
        std::vector<VkDescriptorSetLayoutBinding> bindings(nb + first);
        if (first)
            bindings[0] = {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1,
                           VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
        for (uint32_t i = 0; i < nb; ++i)
            bindings[i + first] = {i + first, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                                   VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
        VkDescriptorSetLayoutCreateInfo dslci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        dslci.bindingCount = nb + first;
        dslci.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(dev, &dslci, nullptr, &p.set_layout));
        VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        plci.setLayoutCount = 1;
        plci.pSetLayouts = &p.set_layout;
        const VkPushConstantRange phase{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(uint32_t)};
        plci.pushConstantRangeCount = 1;
        plci.pPushConstantRanges = &phase;
        VK_CHECK(vkCreatePipelineLayout(dev, &plci, nullptr, &p.layout));
        VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        smci.codeSize = spirv.size() * sizeof(uint32_t);
        smci.pCode = spirv.data();
        VK_CHECK(vkCreateShaderModule(dev, &smci, nullptr, &p.module));
        VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        cpci.stage.module = p.module;
        cpci.stage.pName = "main";
        cpci.layout = p.layout;
        if (const VkResult r =
                vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, nullptr, &p.pipeline);
            r != VK_SUCCESS)
            // NVIDIA's driver answers VK_ERROR_UNKNOWN to a shader whose private arrays pass
            // about 16 KiB an invocation (docs/benchmarks.md): the likely cause, named.
            ErrorExit(std::string("Vulkan: the driver refused the compute pipeline (") +
                      ResultName(r) + ") on " + d.name +
                      ": the shader's private arrays may be too large for it (NVIDIA's takes about "
                      "16 KiB an invocation); -gpu_scratch on (the default on GPUs) keeps them in "
                      "buffers");
        it = d.pipelines.emplace(key, std::move(p)).first;
    }
    return it->second;
}

void GpuDevice::RunStages(const std::vector<Stage> &stages, const std::vector<Binding> &bindings) {
    Impl &d = *impl_;
    VkDevice dev = d.device;
    CHECK(!d.ray_queries || d.tlas != VK_NULL_HANDLE);  // BuildScene first
    // With ray queries the acceleration structure is binding 0 and the buffers follow it.
    const uint32_t first = d.ray_queries ? 1 : 0;
    const uint32_t nb = static_cast<uint32_t>(bindings.size());
    // The stages with invocations, each code's pipeline looked up once (its key hashes the
    // whole code, and a run of waves has thousands of stages of one code). (Two codes of one key
    // would evict each other's pipeline from the cache while the other is held: refused.)
    std::vector<std::pair<Stage, const Pipeline *>> runs;
    std::vector<std::pair<const std::vector<uint32_t> *, const Pipeline *>> codes;
    for (const Stage &stage : stages) {
        CHECK(stage.local_size_x > 0);
        if (stage.invocations == 0) continue;
        auto code = std::find_if(codes.begin(), codes.end(),
                                 [&](const auto &c) { return c.first == stage.spirv; });
        if (code == codes.end()) {
            for (const auto &c : codes)
                CHECK(PipelineKey(*c.first, nb) != PipelineKey(*stage.spirv, nb) ||
                      *c.first == *stage.spirv);
            codes.push_back({stage.spirv, &PipelineFor(d, *stage.spirv, nb)});
            code = codes.end() - 1;
        }
        runs.push_back({stage, code->second});
    }
    d.stage_seconds.clear();
    if (runs.empty()) return;
    // One descriptor set for every stage: their layouts are defined alike, so compatible.
    const Pipeline &p = *runs[0].second;

    // Storage buffers, kept between runs and grown when too small.
    if (d.run_buffers.size() < nb) d.run_buffers.resize(nb);
    if (d.scratch_buffers.size() < nb) d.scratch_buffers.resize(nb);
    if (d.accum_buffers.size() < nb) d.accum_buffers.resize(nb);
    if (d.readback_buffers.size() < nb) d.readback_buffers.resize(nb);
    for (uint32_t i = 0; i < nb; ++i) {
        if (const uint64_t size = bindings[i].scratch) {
            if (size > d.limits.maxStorageBufferRange)
                ErrorExit("Vulkan: scratch of " + std::to_string(size) + " bytes exceeds " +
                          d.name + "'s maxStorageBufferRange of " +
                          std::to_string(d.limits.maxStorageBufferRange));
            Buffer &b = d.scratch_buffers[i];
            if (!b.buffer || b.size < size) {
                d.Destroy(b);
                b = d.Create(size,
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             false);
            }
            CHECK(!bindings[i].zeroed || size % 4 == 0);  // vkCmdFillBuffer's unit
            continue;
        }
        if (!bindings[i].host) {
            CHECK(bindings[i].resident >= 0 &&
                  bindings[i].resident < static_cast<int>(d.resident.size()));
            continue;
        }
        const std::vector<uint8_t> &data = *bindings[i].host;
        const size_t size = data.size();
        if (size > d.limits.maxStorageBufferRange)
            ErrorExit("Vulkan: a buffer of " + std::to_string(size) + " bytes exceeds " + d.name +
                      "'s maxStorageBufferRange of " +
                      std::to_string(d.limits.maxStorageBufferRange));
        if (bindings[i].accumulator) {
            CHECK(size % 4 == 0);  // vkCmdFillBuffer's unit
            Buffer &b = d.accum_buffers[i], &back = d.readback_buffers[i];
            if (!b.buffer || b.size < size) {
                d.Destroy(b);
                d.Destroy(back);
                b = d.Create(size,
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                 VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             false);
                back = d.Create(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, true);
            }
            continue;
        }
        Buffer &b = d.run_buffers[i];
        if (!b.buffer || b.size < size) {
            d.Destroy(b);
            b = d.Create(size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
        }
        if (size > 0) std::memcpy(b.mapped, data.data(), size);
    }

    std::vector<VkDescriptorPoolSize> sizes;
    if (first) sizes.push_back({VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1});
    if (nb > 0) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nb});
    CHECK(!sizes.empty());
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 1;
    dpci.poolSizeCount = static_cast<uint32_t>(sizes.size());
    dpci.pPoolSizes = sizes.data();
    VkDescriptorPool dpool;
    VK_CHECK(vkCreateDescriptorPool(dev, &dpci, nullptr, &dpool));
    VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsai.descriptorPool = dpool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &p.set_layout;
    VkDescriptorSet set;
    VK_CHECK(vkAllocateDescriptorSets(dev, &dsai, &set));
    VkWriteDescriptorSetAccelerationStructureKHR as_write{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    as_write.accelerationStructureCount = 1;
    as_write.pAccelerationStructures = &d.tlas;
    std::vector<VkDescriptorBufferInfo> infos(nb);
    std::vector<VkWriteDescriptorSet> writes(nb + first, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET});
    if (first) {
        writes[0].pNext = &as_write;
        writes[0].dstSet = set;
        writes[0].dstBinding = 0;
        writes[0].descriptorCount = 1;
        writes[0].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    }
    for (uint32_t i = 0; i < nb; ++i) {
        // The range is the caller's size, not the buffer's capacity, so .length() in the shader
        // is right (a range may not be 0: empty buffers get 16 bytes, the least Create makes).
        const Binding &bi = bindings[i];
        const VkDeviceSize size = bi.scratch ? bi.scratch
                                  : bi.host  ? bi.host->size()
                                             : d.resident_size[bi.resident];
        const VkBuffer buffer = bi.scratch       ? d.scratch_buffers[i].buffer
                                : bi.accumulator ? d.accum_buffers[i].buffer
                                : bi.host        ? d.run_buffers[i].buffer
                                                 : d.resident[bi.resident].buffer;
        infos[i] = {buffer, 0, size > 0 ? size : 16};
        writes[i + first].dstSet = set;
        writes[i + first].dstBinding = i + first;
        writes[i + first].descriptorCount = 1;
        writes[i + first].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i + first].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(dev, nb + first, writes.data(), 0, nullptr);

    // Groups beyond the x limit go in y (see the header for how the shader indexes then).
    const auto groups_of = [&](const Stage &st) {
        const uint64_t groups = (uint64_t{st.invocations} + st.local_size_x - 1) / st.local_size_x;
        const uint32_t gx =
            static_cast<uint32_t>(std::min<uint64_t>(groups, d.limits.maxComputeWorkGroupCount[0]));
        const uint64_t gy = (groups + gx - 1) / gx;
        if (gy > d.limits.maxComputeWorkGroupCount[1])
            ErrorExit("Vulkan: " + std::to_string(st.invocations) + " invocations in groups of " +
                      std::to_string(st.local_size_x) + " exceed " + d.name +
                      "'s work group limits");
        return std::pair<uint32_t, uint32_t>(gx, static_cast<uint32_t>(gy));
    };
    for (const auto &run : runs) groups_of(run.first);  // (before anything is recorded)

    VkCommandBuffer cb = d.BeginCommands();
    const uint32_t slots = static_cast<uint32_t>(runs.size()) + 1;
    const bool timed = d.timestamp_bits > 0;
    if (timed && d.timestamp_slots < slots) {
        if (d.timestamps) vkDestroyQueryPool(dev, d.timestamps, nullptr);
        VkQueryPoolCreateInfo qpci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qpci.queryCount = slots;
        VK_CHECK(vkCreateQueryPool(dev, &qpci, nullptr, &d.timestamps));
        d.timestamp_slots = slots;
    }
    if (timed) vkCmdResetQueryPool(cb, d.timestamps, 0, slots);
    const auto barrier = [&](VkPipelineStageFlags from, VkAccessFlags written,
                             VkPipelineStageFlags to, VkAccessFlags used) {
        VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        b.srcAccessMask = written;
        b.dstAccessMask = used;
        vkCmdPipelineBarrier(cb, from, to, 0, 1, &b, 0, nullptr, 0, nullptr);
    };
    const auto accumulators = [&](const auto &each) {
        for (uint32_t i = 0; i < nb; ++i)
            if (bindings[i].accumulator && !bindings[i].host->empty()) each(i);
    };
    bool any_accumulator = false, any_fill = false;
    accumulators([&](uint32_t i) {
        vkCmdFillBuffer(cb, d.accum_buffers[i].buffer, 0, bindings[i].host->size(), 0);
        any_accumulator = any_fill = true;
    });
    for (uint32_t i = 0; i < nb; ++i)
        if (bindings[i].scratch && bindings[i].zeroed) {
            vkCmdFillBuffer(cb, d.scratch_buffers[i].buffer, 0, bindings[i].scratch, 0);
            any_fill = true;
        }
    if (any_fill)
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    for (size_t k = 0; k < runs.size(); ++k) {
        if (k > 0)  // a stage reads what the stages before it wrote
            barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                    VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        const auto [gx, gy] = groups_of(runs[k].first);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, runs[k].second->pipeline);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, runs[k].second->layout, 0, 1,
                                &set, 0, nullptr);
        vkCmdPushConstants(cb, runs[k].second->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                           sizeof(uint32_t), &runs[k].first.phase);
        if (timed && k == 0)  // (once the fills before it are done)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, d.timestamps, 0);
        vkCmdDispatch(cb, gx, gy, 1);
        if (timed)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, d.timestamps,
                                static_cast<uint32_t>(k) + 1);
    }
    if (any_accumulator) {
        barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        accumulators([&](uint32_t i) {
            const VkBufferCopy region{0, 0, bindings[i].host->size()};
            vkCmdCopyBuffer(cb, d.accum_buffers[i].buffer, d.readback_buffers[i].buffer, 1,
                            &region);
        });
    }
    // A fence makes device writes available but not visible to the host; this barrier does.
    barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
            VK_ACCESS_HOST_READ_BIT);
    d.SubmitAndWait(cb);
    vkDestroyDescriptorPool(dev, dpool, nullptr);
    if (timed) {
        std::vector<uint64_t> ticks(slots);
        VK_CHECK(vkGetQueryPoolResults(dev, d.timestamps, 0, slots, slots * sizeof(uint64_t),
                                       ticks.data(), sizeof(uint64_t),
                                       VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        const uint64_t mask =
            d.timestamp_bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << d.timestamp_bits) - 1;
        for (uint32_t k = 1; k < slots; ++k)
            d.stage_seconds.push_back(double((ticks[k] - ticks[k - 1]) & mask) *
                                      d.limits.timestampPeriod * 1e-9);
    }

    for (uint32_t i = 0; i < nb; ++i) {
        const Binding &bi = bindings[i];
        if (!bi.host || !bi.read_back || bi.host->empty()) continue;
        const Buffer &from = bi.accumulator ? d.readback_buffers[i] : d.run_buffers[i];
        std::memcpy(bi.host->data(), from.mapped, bi.host->size());
    }
}

}  // namespace dayflux::vk
