#include "raytrace/engine.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <utility>
#include <vector>

#include "raytrace/core/tables.h"
#include "raytrace/embree/cpu_contrib.h"
#include "raytrace/materials.h"
#include "raytrace/packing.h"
#include "util/errors.h"
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
#include "raytrace/vulkan/raytracing.h"
#include "raytrace/vulkan/vulkan_contrib.h"
#endif

namespace dayflux {

namespace {

// RADIANCE reports an undefined name in -b only when a ray first takes it, which may be never
// (all-zero columns, no word) or hours into a run: we refuse it before tracing.
void CheckBinExpressions(const std::vector<TrackedModifier> &tracked,
                         const MakeContext &make_context) {
    std::vector<std::unique_ptr<cal::Context>> contexts(tracked.size());
    for (size_t k = 0; k < tracked.size(); ++k) {
        const int of = tracked[k].context_of >= 0 ? tracked[k].context_of : static_cast<int>(k);
        if (!contexts[of]) contexts[of] = make_context(of);
        const cal::Context &cx = *contexts[of];
        const cal::Expression bin =
            cx.CompileInterpreted(tracked[k].bin_expression, FileLoc{"-b", 0});  // names only
        const std::vector<std::string> undefined = cx.UndefinedNames(bin);
        if (!undefined.empty())
            ErrorExit("-b " + tracked[k].bin_expression + " (modifier '" + tracked[k].name +
                      "'): undefined variable '" + undefined.front() + "'");
    }
}

}  // namespace

std::unique_ptr<ContribEngine> CreateContribEngine(const FlatScene &scene,
                                                   const ContribOptions &options,
                                                   const std::vector<TrackedModifier> &tracked,
                                                   const MakeContext &make_context,
                                                   const EngineOptions &engine) {
    if (engine.backend != "embree" && engine.backend != "vulkan")
        ErrorExit("unknown backend '" + engine.backend + "' (embree or vulkan)");
    CheckBinExpressions(tracked, make_context);
    auto table = std::make_unique<SceneMaterials>(scene, tracked);
    PackedScene packed = PackScene(scene, *table, tracked, options);
    if (engine.backend == "vulkan") {
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
        std::string why = UnsupportedOnGpu(packed, options);
        if (why.empty()) {
            std::unique_ptr<ContribEngine> gpu = CreateVulkanContribEngine(
                scene, packed, options, tracked, make_context, engine, &why);
            if (gpu) return gpu;
        }
        Warning("the Vulkan backend cannot take this run (" + why + "); using Embree");
#else
        Warning("this build has no Vulkan backend; using Embree");
#endif
    }
    std::unique_ptr<Backend> backend = CreateEmbreeBackend();
    if (engine.wrap_cpu_backend) backend = engine.wrap_cpu_backend(std::move(backend));
    return CreateCpuContribEngine(scene, tracked, std::move(table), std::move(packed), options,
                                  make_context, std::move(backend), engine.cpu_paths_at_once);
}

std::string DescribeGpuDevices() {
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
    std::string why, text;
    for (const std::string &line : vk::GpuDevice::Describe(&why)) text += line + "\n";
    return text.empty() ? why + "\n" : text;
#else
    return "this build has no Vulkan backend\n";
#endif
}

void ContribEngine::TraceKeyed(const double *rays, size_t n, const uint64_t *keys, int replica,
                               double *records) {
    const size_t width = 3 * static_cast<size_t>(Columns());
    const size_t batch = std::max<size_t>(1, BatchRays());
    std::vector<std::pair<size_t, size_t>> runs;  // [begin, end)
    for (size_t k = 0; k < n; ++k) {
        if (!runs.empty() && runs.back().second == k && k - runs.back().first < batch &&
            keys[k] == keys[k - 1] + 1)
            ++runs.back().second;
        else
            runs.push_back({k, k + 1});
    }
    tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
        const auto [begin, end] = runs[r];
        Trace(rays + 6 * begin, end - begin, keys[begin], replica, records + begin * width);
    });
}

void TraceReplicas(ContribEngine &engine, const double *rays, size_t n, uint64_t first_index,
                   int replicas, double *sums, double *variances) {
    const size_t len = n * 3 * static_cast<size_t>(engine.Columns());
    if (replicas <= 1) {
        engine.Trace(rays, n, first_index, 0, sums);
        return;
    }
    if (variances && engine.TraceWithVariances(rays, n, first_index, sums, variances)) return;
    std::vector<double> one(len), mean(len, 0.0), squares(len, 0.0);
    for (int k = 0; k < replicas; ++k) {
        std::fill(one.begin(), one.end(), 0.0);
        engine.Trace(rays, n, first_index, k, one.data());
        for (size_t j = 0; j < len; ++j) mean[j] += one[j], squares[j] += one[j] * one[j];
    }
    for (size_t j = 0; j < len; ++j) {
        const double m = mean[j] / replicas;
        sums[j] += m;
        // the variance of the mean of the replicas
        if (variances)
            variances[j] +=
                std::max(0.0, (squares[j] - replicas * m * m) / (replicas - 1) / replicas);
    }
}

void WarnCoreReports(uint32_t reports, uint64_t dropped) {
    static std::atomic<uint32_t> said{0};
    const uint32_t fresh = reports & ~said.fetch_or(reports);
    if (fresh & core::kReportBadBin) Warning("bad bin number (ignored)");
    if (fresh & core::kReportBsdfFrame) Warning("BSDF: illegal orientation vector");
    if (fresh & core::kReportStackFull)
        Warning("the estimator's ray stack overflowed; " + std::to_string(dropped) +
                " rays were dropped (results are low)");
    if (fresh & core::kReportFixedRange)
        Warning(
            "a contribution beyond the GPU paths engine's fixed point (8192 times its "
            "sources' radiance) or not a number was left out; -gpu_engine tasks holds any float");
}

}  // namespace dayflux
