// Choosing a Vulkan device, the same way for every dayflux device class: the one the caller
// names (an index or part of the name: rcontrib-gpu's -device), else a discrete GPU, else an
// integrated one, else a CPU device (lavapipe) where those are allowed.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <string>
#include <vector>

namespace dayflux::vk {

// A Vulkan 1.2 instance; VK_NULL_HANDLE with *why when there is no driver.
VkInstance CreateInstance(std::string *why);

// lacks(device) says what a device is missing for the caller ("" when it has everything).
// Returns the devices to use, best first: those `want` names (a comma-separated list of indices
// or name parts; one naming the same device twice opens it twice), else every device of the
// best kind (all discrete GPUs, say). Returns none and sets *why (with each device's
// shortcoming) when none qualifies; a device `want` names counts even when it is a CPU device.
std::vector<VkPhysicalDevice> ChooseDevices(
    VkInstance instance, const std::function<std::string(VkPhysicalDevice)> &lacks, bool allow_cpu,
    const std::string &want, const std::string &what, std::string *why);

// The first queue family with compute; false when there is none.
bool ComputeQueueFamily(VkPhysicalDevice device, uint32_t *family);

}  // namespace dayflux::vk
