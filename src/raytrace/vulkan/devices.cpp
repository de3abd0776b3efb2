#include "raytrace/vulkan/devices.h"

#include <cstdlib>
#include <cstring>
#include <vector>

namespace dayflux::vk {

VkInstance CreateInstance(std::string *why) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "dayflux";
    app.apiVersion = VK_API_VERSION_1_2;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS) {
        *why = "no Vulkan 1.2 driver (vkCreateInstance failed)";
        return VK_NULL_HANDLE;
    }
    return instance;
}

VkPhysicalDevice ChooseDevice(VkInstance instance,
                              const std::function<std::string(VkPhysicalDevice)> &lacks,
                              bool allow_cpu, const std::string &what, std::string *why) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    if (devices.empty()) {
        *why = "no Vulkan device";
        return VK_NULL_HANDLE;
    }
    const char *want = std::getenv("DAYFLUX_VULKAN_DEVICE");
    const bool named = want && *want;
    std::string rejected;  // why each device was passed over
    const auto reject = [&](const char *name, const std::string &reason) {
        rejected += std::string(rejected.empty() ? "" : "; ") + name + reason;
    };
    int chosen = -1, score = -1;
    for (uint32_t i = 0; i < n; ++i) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        if (named) {
            char *end;
            const long idx = std::strtol(want, &end, 10);
            const bool match = *end == '\0' ? idx == static_cast<long>(i)
                                            : std::strstr(p.deviceName, want) != nullptr;
            if (!match) continue;
        }
        if (const std::string missing = lacks(devices[i]); !missing.empty()) {
            reject(p.deviceName, " lacks" + missing);
            continue;
        }
        const bool cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        if (cpu && !allow_cpu && !named) {
            reject(p.deviceName, " is a CPU device (DAYFLUX_VULKAN_DEVICE or -device can name it)");
            continue;
        }
        const int s = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? 3 : cpu ? 1 : 2;
        if (s > score) score = s, chosen = static_cast<int>(i);
    }
    if (chosen < 0) {
        *why = named ? "no Vulkan device " + what + " matches DAYFLUX_VULKAN_DEVICE=" + want
                     : "no Vulkan device " + what;
        if (!rejected.empty()) *why += " (" + rejected + ")";
        return VK_NULL_HANDLE;
    }
    return devices[chosen];
}

bool ComputeQueueFamily(VkPhysicalDevice device, uint32_t *family) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &n, nullptr);
    std::vector<VkQueueFamilyProperties> qf(n);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &n, qf.data());
    for (uint32_t i = 0; i < n; ++i)
        if (qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
            *family = i;
            return true;
        }
    return false;
}

}  // namespace dayflux::vk
