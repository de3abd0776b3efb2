// rcontrib's estimator on a Vulkan device with ray queries: the scene's triangles in an
// acceleration structure, and a compute shader (src/shaders/contrib.comp) specialised to the run:
// its options, the tracked modifiers' bin expressions compiled from calcomp to GLSL, the scene's
// materials and sources as tables. Results equal the CPU integrator's (contrib.h) within noise.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "raytrace/contrib.h"
#include "scene/flatten.h"

namespace dayflux {

class VulkanContribIntegrator {
  public:
    // Returns nullptr and says why when there is no Vulkan device with ray queries or the run
    // needs what the GPU integrator does not do yet (-ss above 16, bin or pattern expressions
    // GLSL cannot express, ...); the caller then uses the CPU integrator.
    // make_context(k) gives the context modifier k's bins are compiled in, for each k with a
    // context of its own (TrackedModifier::context_of). Each task accumulates its
    // contributions in double, or in float with float_accumulators (half the memory). -I
    // sensors split their first hemisphere between tasks, so a task's sums are short and float
    // costs little there (a uniform sky at -ad 50000: 4e-8 relative either way, the rounding of
    // float coefficients); a view ray's first hemisphere is one task's, where float sums of
    // 50000 samples lose about 1e-6. Records are summed in double on the host.
    static std::unique_ptr<VulkanContribIntegrator> Create(
        const FlatScene &scene, const ContribOptions &options,
        const std::vector<TrackedModifier> &tracked,
        const std::function<std::unique_ptr<cal::Context>(int)> &make_context,
        bool float_accumulators, std::string *why);
    ~VulkanContribIntegrator();

    const std::string &DeviceName() const;
    int Columns() const { return columns_; }
    // Traces n input rays (origin and direction, 6 doubles each; a zero direction contributes
    // nothing) and adds each one's contributions to its record (Columns() x 3 doubles) in
    // records. first_index keys the random numbers, as does replica (-se). One call at a time:
    // the device is not shared between threads.
    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) const;

    struct Impl;

  private:
    explicit VulkanContribIntegrator(std::unique_ptr<Impl> impl, int columns);
    std::unique_ptr<Impl> impl_;
    int columns_ = 0;
};

}  // namespace dayflux
