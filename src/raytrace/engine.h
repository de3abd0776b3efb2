// One interface for the programs that trace contribution coefficients: an engine runs the
// estimator core (raytrace/core) on a backend, the CPU with Embree or a Vulkan GPU, created from
// the run's options. Where the GPU cannot take a run (no device, or what its core does not
// trace), that is decided before anything is compiled or uploaded, one line says why, and the
// CPU takes it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "raytrace/backend.h"
#include "raytrace/contrib.h"
#include "scene/flatten.h"

namespace dayflux {

// How a GPU finds hits: ray queries where the device has them (auto), ray queries, or a walk of
// our own BVH (raytrace/bvh.h; NVIDIA's H100 and H200 have no ray queries).
enum class GpuTraversal { kAuto, kRayQuery, kBvh };
// Where a GPU keeps each task's ray stack and hemisphere rows: storage buffers (scratch), which
// GPUs need (NVIDIA's driver refuses pipelines with more than about 16 KiB of private arrays an
// invocation), or private arrays, which lavapipe's LLVM compiles over four times sooner; auto:
// private arrays on CPU devices only.
enum class GpuScratch { kAuto, kOn, kOff };
// The GPU's per-task accumulators: two floats an entry, the second holding what the first's
// rounding lost (pairs: double's precision without shaderFloat64, the default), float (half the
// memory; a sensor's first hemisphere is split between tasks, so their sums are short), or
// double (needs shaderFloat64). Records are summed in double on the host.
enum class GpuAccum { kPair, kFloat, kDouble };
// What spirv-opt does to the GPU's shader before the driver compiles it (issue 42's compile
// time): -O, -Os, nothing, or auto: nothing on CPU devices, whose LLVM compiles and runs
// unoptimised SPIR-V sooner (lavapipe: about 3 s less a pipeline, traces 1.1-1.3x sooner), -O
// on GPUs (until NVIDIA's figures say otherwise).
enum class GpuSpirvOpt { kAuto, kPerformance, kSize, kNone };
// How the GPU shares out a run (issue 42's step 3): tasks, an invocation each walking a sensor's
// slice of first-hemisphere rows whole, into a record of its own (float pairs, slices summed
// after); or paths, whose first phase runs the same tasks but keeps each first-hemisphere cell's
// ray and random state in device memory, and whose second phase walks those cells' paths, each
// invocation one path after another, every add into the sensor's one record in 64-bit fixed
// point by 32-bit atomics: exact sums, so the same bytes whatever order the adds come in. Its
// records hold coefficients up to 32768 (-V+: that times a bound on the tracked sources'
// radiance; a pattern on one sends the run to the tasks engine); rays without -I have no
// cells, and the first phase traces them whole.
enum class GpuEngine { kTasks, kPaths };

struct EngineOptions {
    std::string backend = "embree";  // "embree" or "vulkan"
    // Vulkan devices: a comma-separated list of indices or parts of names ("" chooses: every
    // discrete GPU, else an integrated one; lavapipe only when named).
    std::string device;
    GpuTraversal traversal = GpuTraversal::kAuto;
    GpuScratch scratch = GpuScratch::kAuto;
    GpuAccum accumulators = GpuAccum::kPair;
    // Bins and patterns (calcomp) on the GPU in double rather than float (needs shaderFloat64).
    // By default no shader holds a double: the engine runs on devices without fp64 (Apple's,
    // Intel's) and at full rate on consumer GPUs, which run fp64 at 1/32-1/64.
    bool gpu_double_cal = false;
    bool NeedsFloat64() const { return accumulators == GpuAccum::kDouble || gpu_double_cal; }
    GpuSpirvOpt spirv_opt = GpuSpirvOpt::kAuto;
    GpuEngine gpu_engine = GpuEngine::kTasks;
    // For tests: false sums a sensor's slices on the host, each task's record read back (as
    // with float accumulators); a bound on the tasks a dispatch takes (0: as memory allows).
    bool gpu_slice_sums = true;
    int gpu_tasks_per_dispatch = 0;
    // For benchmarks (bench/gpu_replay_bench.cpp's -scratch_mib): the device memory a dispatch
    // may take for its invocations' stacks and rows, its records and the paths engine's cells
    // (0: a quarter of the GPU's, at most 2 GiB; fixed shares on CPU devices). The paths
    // engine's walkers get half of it.
    uint64_t gpu_scratch_bytes = 0;
    // The paths engine's waves (-gpu_waves): its walkers first take this many steps together,
    // each a dispatch that takes every walker's path to its next ray and one that finds those
    // rays' nearest hits (the traversal apart from the shading, as a wavefront engine has it),
    // before one dispatch walks their paths to the end. The same sums for any number.
    int gpu_waves = 0;
    // For benchmarks (bench/gpu_replay_bench.cpp): the GPU logs up to this many of the rays it
    // traces (nearest-hit queries), for ContribEngine::ReplayLoggedRays.
    uint64_t gpu_ray_log = 0;
    // The CPU: the paths of a sensor's first-hemisphere cells (-I) walked at once by a thread,
    // their rays traced together in Embree's packets (1: one after the other; at most 16).
    int cpu_paths_at_once = 8;
    // For benchmarks (bench/ray_replay_bench.cpp) and tests: wraps the CPU's ray caster, to
    // count or record the rays the integrator traces. Empty: Embree as it is.
    std::function<std::unique_ptr<Backend>(std::unique_ptr<Backend>)> wrap_cpu_backend;
};

class ContribEngine {
  public:
    virtual ~ContribEngine() = default;
    // What traces: "Embree 3.13.5", "vulkan: NVIDIA H100 80GB HBM3".
    virtual std::string Label() const = 0;
    // Columns of a record: all tracked modifiers' bins.
    virtual int Columns() const = 0;
    // Input rays per Trace call that keep the engine busy without holding much memory.
    virtual size_t BatchRays() const = 0;
    // Traces n input rays (origin and direction, 6 doubles each; a zero direction contributes
    // nothing) and adds each one's contributions to its record (Columns() x 3 doubles) in
    // records. first_index keys the random numbers, as does replica (-se): with the same seed,
    // every engine draws the same numbers for the same record, ray and bounce. Safe to call
    // from several threads at once.
    virtual void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
                       double *records) = 0;
    // As Trace, ray i's numbers keyed by keys[i] (ascending, not consecutive: the sensor cache's
    // records). Here, one Trace per run of consecutive keys, the runs side by side; a GPU
    // engine takes them in one dispatch.
    virtual void TraceKeyed(const double *rays, size_t n, const uint64_t *keys, int replica,
                            double *records);
    // As TraceKeyed, but each ray's first hemisphere (-I) is traced as `slices` slices of its
    // rows (with shares of its light sources), and each slice's record is kept apart:
    // slice_records holds n x slices records (zeroed by the caller), ray by ray. A slice beyond
    // the hemisphere's rows adds nothing. -target_error reads the spread of a pair of replicas
    // slice by slice. False where the engine cannot do it (nothing is traced).
    virtual bool TraceSlices(const double *rays, size_t n, const uint64_t *keys, int replica,
                             int slices, double *slice_records) {
        (void)rays, (void)n, (void)keys, (void)replica, (void)slices, (void)slice_records;
        return false;
    }

    // As Trace, and adds to variances (as records) each entry's variance, where the engine
    // estimates it itself (-target_error's, from its passes' replicas); false where it does not
    // (nothing is traced): -se then traces replicas (TraceReplicas).
    virtual bool TraceWithVariances(const double *rays, size_t n, uint64_t first_index,
                                    double *records, double *variances) {
        (void)rays, (void)n, (void)first_index, (void)records, (void)variances;
        return false;
    }

    // For benchmarks (bench/gpu_replay_bench.cpp), the GPU engine's: the nearest-hit queries
    // traced since it was made (0 where not counted), and the device's seconds in each stage of
    // its dispatches (trace, slice sums; empty without timestamps).
    virtual uint64_t RaysTraced() const { return 0; }
    virtual std::vector<double> StageSeconds() const { return {}; }
    // The rays logged (EngineOptions::gpu_ray_log) traced again by a kernel that only finds their
    // nearest hits (the trace's own Intersect), `passes` times on the first device: the fastest
    // pass's device and wall seconds, the rays and how many hit. Nothing where none were logged.
    struct ReplayResult {
        uint64_t rays = 0, hits = 0;
        double device_seconds = 0, wall_seconds = 0;
    };
    virtual ReplayResult ReplayLoggedRays(int passes) {
        (void)passes;
        return {};
    }
};

// make_context(k) gives a calcomp context with every -e/-f and tracked modifier k's -p applied,
// for each k with a context of its own (TrackedModifier::context_of).
using MakeContext = std::function<std::unique_ptr<cal::Context>(int)>;

// The engine options.backend names (the CPU where the GPU cannot take the run, with one line on
// stderr saying why). Bad input (unknown materials, ...) is reported as UserError.
std::unique_ptr<ContribEngine> CreateContribEngine(const FlatScene &scene,
                                                   const ContribOptions &options,
                                                   const std::vector<TrackedModifier> &tracked,
                                                   const MakeContext &make_context,
                                                   const EngineOptions &engine);

// The Vulkan devices this build sees, one line each (their index, name, type, ray queries or
// not), or why there are none.
std::string DescribeGpuDevices();

// -se: every input ray traced as `replicas` independent replicas (each with -ad / replicas, set
// by the caller); sums gets each ray's mean record added, variances (when not null) the
// variance of that mean, estimated from the replicas' spread; or, by an engine that estimates
// them itself (TraceWithVariances), the record and its variances from one trace.
void TraceReplicas(ContribEngine &engine, const double *rays, size_t n, uint64_t first_index,
                   int replicas, double *sums, double *variances);

// Warnings about what the core reported (tables' kReport* flags), each said once per process.
void WarnCoreReports(uint32_t reports, uint64_t dropped);

}  // namespace dayflux
