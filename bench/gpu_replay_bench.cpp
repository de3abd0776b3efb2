// Issue 42's measure of the GPU engine's limit, the GPU twin of ray_replay_bench.cpp: the rays a
// run traces, replayed on the same device by a kernel that only finds their nearest hits (the
// trace's own BVH walk or ray query and hit refinement, contrib.comp's DAYFLUX_REPLAY). Over the
// sensors read from stdin (rcontrib-gpu's options, with -backend vulkan and -device, and scene
// as arguments, text rays):
//   1. the run, once to compile its pipeline (not timed), then timed (-repeat N times, the
//      fastest kept): wall seconds, the device's seconds per stage (timestamps; the tasks
//      engine: trace, slice sums; -gpu_engine paths: the tasks' sources and cells, the cells'
//      paths, and with -gpu_waves the waves' walks to their next rays and their hits: stage3_s
//      and stage4_s, the last columns) and the nearest-hit queries it traced (the engine counts
//      them);
//   2. the run again over every K-th sensor (-record_every K), logging its rays (at most
//      -log_rays M), and those rays replayed N times, the fastest pass kept.
// GPU efficiency = (rays a second of the run) / (rays a second of the replay), both by the
// device's own timestamps where it has them (else wall time).
// -scratch_mib S gives the engine S MiB of device memory a dispatch (EngineOptions::
// gpu_scratch_bytes; the paths engine's walkers half of it) in place of the device's budget.
// usage: gpu_replay_bench [-record_every K] [-repeat N] [-log_rays M] [-scratch_mib S]
//        rcontrib-gpu-options... scene... < sensors
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/run.h"
#include "replay_common.h"
#include "util/errors.h"

namespace dayflux {
namespace {

using Clock = std::chrono::steady_clock;

std::unique_ptr<ContribEngine> MakeEngine(const RcontribOptions &o, const FlatScene &flat,
                                          uint64_t log_rays, uint64_t scratch_mib) {
    EngineOptions engine = o.engine;
    engine.gpu_ray_log = log_rays;
    engine.gpu_scratch_bytes = scratch_mib << 20;
    std::unique_ptr<ContribEngine> e = CreateRunEngine(o, flat, o.contrib, engine);
    if (e->Label().rfind("vulkan", 0) != 0)
        ErrorExit("no Vulkan engine for this run (" + e->Label() + ")");
    return e;
}

struct RunTimes {
    double wall = 0;
    std::vector<double> stages;  // the device's, per stage
    uint64_t rays = 0;
};

RunTimes TimedRun(ContribEngine &e, const std::vector<double> &rays) {
    const size_t n = rays.size() / 6;
    std::vector<double> records(n * 3 * static_cast<size_t>(e.Columns()), 0.0);
    const uint64_t rays_before = e.RaysTraced();
    const std::vector<double> stages_before = e.StageSeconds();
    const Clock::time_point start = Clock::now();
    e.Trace(rays.data(), n, 0, 0, records.data());
    RunTimes t;
    t.wall = std::chrono::duration<double>(Clock::now() - start).count();
    t.rays = e.RaysTraced() - rays_before;
    t.stages = e.StageSeconds();
    for (size_t k = 0; k < stages_before.size(); ++k) t.stages[k] -= stages_before[k];
    return t;
}

double Total(const std::vector<double> &v) {
    double s = 0;
    for (double x : v) s += x;
    return s;
}

int Main(int argc, char **argv) {
    std::vector<std::string> args(argv, argv + argc);
    size_t every = 1, repeat = 3, log_rays = size_t(1) << 24, scratch_mib = 0;
    bench::TakeCounts(&args,
                      {{"-record_every", &every},
                       {"-repeat", &repeat},
                       {"-log_rays", &log_rays},
                       {"-scratch_mib", &scratch_mib}},
                      {"-scratch_mib"});  // (0: the device's budget)
    std::vector<std::string> header;
    const RcontribOptions o = ParseRcontribOptions(args, &header);
    if (o.engine.backend != "vulkan") ErrorExit("the replay measures the Vulkan backend");
    std::string octree_header;
    const FlatScene flat = ReadRcontribScene(o.scene, &octree_header);
    const std::vector<double> rays = bench::ReadRays(std::cin);

    const std::unique_ptr<ContribEngine> engine = MakeEngine(o, flat, 0, scratch_mib);
    TimedRun(*engine, std::vector<double>(rays.begin(), rays.begin() + 6));  // compiles
    RunTimes run = TimedRun(*engine, rays);
    for (size_t k = 1; k < repeat; ++k) {
        RunTimes again = TimedRun(*engine, rays);
        if (again.wall < run.wall) run = again;
    }

    const std::vector<double> subset = bench::EveryKth(rays, every);
    const std::unique_ptr<ContribEngine> logging = MakeEngine(o, flat, log_rays, scratch_mib);
    TimedRun(*logging, subset);
    const ContribEngine::ReplayResult replay = logging->ReplayLoggedRays(static_cast<int>(repeat));
    if (replay.rays == 0) ErrorExit("no rays logged");

    // The device's clock where it has one, for both.
    const bool device_clock = !run.stages.empty() && replay.device_seconds > 0;
    const double run_s = device_clock ? Total(run.stages) : run.wall;
    const double replay_s = device_clock ? replay.device_seconds : replay.wall_seconds;
    const double run_rate = double(run.rays) / run_s, replay_rate = double(replay.rays) / replay_s;
    std::string device = engine->Label();  // (a CSV field: "llvmpipe (LLVM 15.0.6, 128 bits)")
    std::replace(device.begin(), device.end(), ',', ';');
    std::printf(
        "device,sensors,rays,run_wall_s,run_device_s,stage1_s,stage2_s,run_mrays_s,"
        "replayed_rays,replay_hits,replay_wall_s,replay_device_s,replay_mrays_s,efficiency,"
        "stage3_s,stage4_s\n");
    const auto stage = [&](size_t k) { return k < run.stages.size() ? run.stages[k] : 0.0; };
    std::printf("%s,%zu,%llu,%.4f,%.4f,%.4f,%.4f,%.2f,%llu,%llu,%.4f,%.4f,%.2f,%.3f,%.4f,%.4f\n",
                device.c_str(), rays.size() / 6, static_cast<unsigned long long>(run.rays),
                run.wall, Total(run.stages), stage(0), stage(1), run_rate * 1e-6,
                static_cast<unsigned long long>(replay.rays),
                static_cast<unsigned long long>(replay.hits), replay.wall_seconds,
                replay.device_seconds, replay_rate * 1e-6, run_rate / replay_rate, stage(2),
                stage(3));
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
