#include "raytrace/vulkan/compute.h"

#include <vulkan/vulkan.h>

#include <cstdlib>
#include <cstring>
#include <shaderc/shaderc.hpp>

#include "raytrace/vulkan/devices.h"
#include "util/errors.h"

namespace dayflux::vk {

namespace {

// Every Vulkan call is checked; a failure is an internal error with the call named.
#define VK_CHECK(call)                                                \
    do {                                                              \
        VkResult vk_check_result = (call);                            \
        if (vk_check_result != VK_SUCCESS)                            \
            ErrorExit(std::string("Vulkan: ") + #call + " failed (" + \
                      std::to_string(vk_check_result) + ")");         \
    } while (false)

}  // namespace

struct ComputeDevice::Impl {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t queue_family = 0;
    VkCommandPool pool = VK_NULL_HANDLE;
    std::string name;

    ~Impl() {
        if (device) {
            vkDeviceWaitIdle(device);
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
        ErrorExit("Vulkan: no host-visible memory type");
    }
};

ComputeDevice::ComputeDevice(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ComputeDevice::~ComputeDevice() = default;
const std::string &ComputeDevice::Name() const { return impl_->name; }

std::unique_ptr<ComputeDevice> ComputeDevice::Open(const DeviceRequirements &req,
                                                   std::string *why) {
    auto impl = std::make_unique<Impl>();
    impl->instance = CreateInstance(why);
    if (!impl->instance) return nullptr;
    const auto lacks = [&req](VkPhysicalDevice device) {
        VkPhysicalDeviceFeatures f;
        vkGetPhysicalDeviceFeatures(device, &f);
        return req.float64 && !f.shaderFloat64 ? std::string(" shaderFloat64") : std::string();
    };
    // The GLSL generator's tests run here on lavapipe, so CPU devices count.
    impl->physical = ChooseDevice(impl->instance, lacks, true, "with the features needed", why);
    if (!impl->physical) return nullptr;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(impl->physical, &props);
    impl->name = props.deviceName;
    if (!ComputeQueueFamily(impl->physical, &impl->queue_family)) {
        *why = impl->name + " has no compute queue";
        return nullptr;
    }
    const float priority = 1.f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = impl->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkPhysicalDeviceFeatures features{};
    features.shaderFloat64 = req.float64 ? VK_TRUE : VK_FALSE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.pEnabledFeatures = &features;
    VK_CHECK(vkCreateDevice(impl->physical, &dci, nullptr, &impl->device));
    vkGetDeviceQueue(impl->device, impl->queue_family, 0, &impl->queue);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = impl->queue_family;
    VK_CHECK(vkCreateCommandPool(impl->device, &pci, nullptr, &impl->pool));
    return std::unique_ptr<ComputeDevice>(new ComputeDevice(std::move(impl)));
}

std::vector<uint32_t> ComputeDevice::CompileGlsl(const std::string &source,
                                                 const std::string &name) {
    shaderc::Compiler compiler;
    shaderc::CompileOptions options;
    options.SetOptimizationLevel(shaderc_optimization_level_performance);
    options.SetTargetEnvironment(shaderc_target_env_vulkan, shaderc_env_version_vulkan_1_2);
    auto result = compiler.CompileGlslToSpv(source, shaderc_compute_shader, name.c_str(), options);
    if (result.GetCompilationStatus() != shaderc_compilation_status_success)
        ErrorExit("GLSL compilation of " + name + " failed:\n" + result.GetErrorMessage());
    return {result.cbegin(), result.cend()};
}

void ComputeDevice::Run(const std::vector<uint32_t> &spirv, uint32_t invocations,
                        uint32_t local_size_x, std::vector<std::vector<uint8_t> *> buffers) {
    Impl &d = *impl_;
    VkDevice dev = d.device;
    const uint32_t nb = static_cast<uint32_t>(buffers.size());
    std::vector<VkBuffer> bufs(nb);
    std::vector<VkDeviceMemory> mems(nb);
    for (uint32_t i = 0; i < nb; ++i) {
        VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bci.size = std::max<size_t>(buffers[i]->size(), 16);
        bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        VK_CHECK(vkCreateBuffer(dev, &bci, nullptr, &bufs[i]));
        VkMemoryRequirements mr;
        vkGetBufferMemoryRequirements(dev, bufs[i], &mr);
        VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        mai.allocationSize = mr.size;
        mai.memoryTypeIndex =
            d.MemoryType(mr.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        VK_CHECK(vkAllocateMemory(dev, &mai, nullptr, &mems[i]));
        VK_CHECK(vkBindBufferMemory(dev, bufs[i], mems[i], 0));
        void *p;
        VK_CHECK(vkMapMemory(dev, mems[i], 0, VK_WHOLE_SIZE, 0, &p));
        if (!buffers[i]->empty()) std::memcpy(p, buffers[i]->data(), buffers[i]->size());
        vkUnmapMemory(dev, mems[i]);
    }
    std::vector<VkDescriptorSetLayoutBinding> bindings(nb);
    for (uint32_t i = 0; i < nb; ++i)
        bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                       nullptr};
    VkDescriptorSetLayoutCreateInfo dslci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dslci.bindingCount = nb;
    dslci.pBindings = bindings.data();
    VkDescriptorSetLayout dsl;
    VK_CHECK(vkCreateDescriptorSetLayout(dev, &dslci, nullptr, &dsl));
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &dsl;
    VkPipelineLayout layout;
    VK_CHECK(vkCreatePipelineLayout(dev, &plci, nullptr, &layout));
    VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    smci.codeSize = spirv.size() * sizeof(uint32_t);
    smci.pCode = spirv.data();
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(dev, &smci, nullptr, &module));
    VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = module;
    cpci.stage.pName = "main";
    cpci.layout = layout;
    VkPipeline pipeline;
    VK_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, nullptr, &pipeline));
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nb};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 1;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &ps;
    VkDescriptorPool dpool;
    VK_CHECK(vkCreateDescriptorPool(dev, &dpci, nullptr, &dpool));
    VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsai.descriptorPool = dpool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &dsl;
    VkDescriptorSet set;
    VK_CHECK(vkAllocateDescriptorSets(dev, &dsai, &set));
    std::vector<VkDescriptorBufferInfo> infos(nb);
    std::vector<VkWriteDescriptorSet> writes(nb);
    for (uint32_t i = 0; i < nb; ++i) {
        infos[i] = {bufs[i], 0, VK_WHOLE_SIZE};
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(dev, nb, writes.data(), 0, nullptr);
    VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbai.commandPool = d.pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    VkCommandBuffer cb;
    VK_CHECK(vkAllocateCommandBuffers(dev, &cbai, &cb));
    VkCommandBufferBeginInfo cbbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cb, &cbbi));
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdDispatch(cb, (invocations + local_size_x - 1) / local_size_x, 1, 1);
    VK_CHECK(vkEndCommandBuffer(cb));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK_CHECK(vkCreateFence(dev, &fci, nullptr, &fence));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    VK_CHECK(vkQueueSubmit(d.queue, 1, &si, fence));
    VK_CHECK(vkWaitForFences(dev, 1, &fence, VK_TRUE, UINT64_MAX));
    for (uint32_t i = 0; i < nb; ++i) {
        void *p;
        VK_CHECK(vkMapMemory(dev, mems[i], 0, VK_WHOLE_SIZE, 0, &p));
        std::memcpy(buffers[i]->data(), p, buffers[i]->size());
        vkUnmapMemory(dev, mems[i]);
    }
    vkDestroyFence(dev, fence, nullptr);
    vkFreeCommandBuffers(dev, d.pool, 1, &cb);
    vkDestroyDescriptorPool(dev, dpool, nullptr);
    vkDestroyPipeline(dev, pipeline, nullptr);
    vkDestroyShaderModule(dev, module, nullptr);
    vkDestroyPipelineLayout(dev, layout, nullptr);
    vkDestroyDescriptorSetLayout(dev, dsl, nullptr);
    for (uint32_t i = 0; i < nb; ++i) {
        vkDestroyBuffer(dev, bufs[i], nullptr);
        vkFreeMemory(dev, mems[i], nullptr);
    }
}

}  // namespace dayflux::vk
