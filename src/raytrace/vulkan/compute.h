// A small Vulkan compute runner: device choice, GLSL compiled at run time with shaderc, storage
// buffers in host-visible memory, one dispatch. The GPU backend builds on it; the GLSL generator's
// tests use it to run generated code on lavapipe.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dayflux::vk {

struct DeviceRequirements {
    bool float64 = false;  // shaderFloat64
};

class ComputeDevice {
  public:
    // The device named by DAYFLUX_VULKAN_DEVICE (a name substring or an index), else the first
    // discrete GPU, else any device (lavapipe on machines without a GPU). Returns nullptr and
    // sets *why when there is none that meets the requirements.
    static std::unique_ptr<ComputeDevice> Open(const DeviceRequirements &req, std::string *why);
    ~ComputeDevice();
    ComputeDevice(const ComputeDevice &) = delete;
    ComputeDevice &operator=(const ComputeDevice &) = delete;

    const std::string &Name() const;

    // Compiles a GLSL compute shader (with its #version line) to SPIR-V; errors name `name`.
    static std::vector<uint32_t> CompileGlsl(const std::string &source, const std::string &name);

    // Runs spirv over `invocations` invocations in groups of local_size_x, with storage buffers
    // bound at 0, 1, ... in set 0. Buffers are copied in and, after the run, back out.
    void Run(const std::vector<uint32_t> &spirv, uint32_t invocations, uint32_t local_size_x,
             std::vector<std::vector<uint8_t> *> buffers);

    struct Impl;

  private:
    explicit ComputeDevice(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace dayflux::vk
