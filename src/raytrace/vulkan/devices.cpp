#include "raytrace/vulkan/devices.h"

#include <algorithm>
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

std::vector<VkPhysicalDevice> ChooseDevices(
    VkInstance instance, const std::function<std::string(VkPhysicalDevice)> &lacks, bool allow_cpu,
    const std::string &want, const std::string &what, std::string *why) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    if (devices.empty()) {
        *why = "no Vulkan device";
        return {};
    }
    const bool named = !want.empty();
    std::vector<std::string> names;  // the list's items, or one empty item matching any device
    for (size_t at = 0;;) {
        const size_t comma = want.find(',', at);
        names.push_back(want.substr(at, comma == std::string::npos ? comma : comma - at));
        if (comma == std::string::npos) break;
        at = comma + 1;
    }
    std::string rejected;  // why each device was passed over
    const auto reject = [&](const char *name, const std::string &reason) {
        if (rejected.find(name) == std::string::npos)
            rejected += std::string(rejected.empty() ? "" : "; ") + name + reason;
    };
    // Each item's best match (named), or every device with its score (unnamed).
    std::vector<VkPhysicalDevice> chosen;
    std::vector<int> scores;
    for (const std::string &item : names) {
        int best = -1, best_score = -1;
        for (uint32_t i = 0; i < n; ++i) {
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(devices[i], &p);
            if (named) {
                char *end;
                const long idx = std::strtol(item.c_str(), &end, 10);
                const bool match = *end == '\0' && !item.empty()
                                       ? idx == static_cast<long>(i)
                                       : std::strstr(p.deviceName, item.c_str()) != nullptr;
                if (!match) continue;
            }
            if (const std::string missing = lacks(devices[i]); !missing.empty()) {
                reject(p.deviceName, " lacks" + missing);
                continue;
            }
            const bool cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
            if (cpu && !allow_cpu && !named) {
                reject(p.deviceName, " is a CPU device (-device can name it)");
                continue;
            }
            const int s = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? 3 : cpu ? 1 : 2;
            if (!named) {
                chosen.push_back(devices[i]);
                scores.push_back(s);
            } else if (s > best_score) {
                best_score = s, best = static_cast<int>(i);
            }
        }
        if (named && best >= 0) chosen.push_back(devices[best]);
    }
    if (!named && !chosen.empty()) {  // the best kind only, in enumeration order
        const int top = *std::max_element(scores.begin(), scores.end());
        std::vector<VkPhysicalDevice> kept;
        for (size_t i = 0; i < chosen.size(); ++i)
            if (scores[i] == top) kept.push_back(chosen[i]);
        chosen = kept;
    }
    if (chosen.empty()) {
        *why = named ? "no Vulkan device " + what + " matches '" + want + "'"
                     : "no Vulkan device " + what;
        if (!rejected.empty()) *why += " (" + rejected + ")";
    }
    return chosen;
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
