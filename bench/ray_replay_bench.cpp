// Issue 24's measure of the CPU integrator's limit: the rays one run traces, replayed through
// the ray caster alone. Three passes over the sensors read from stdin (rcontrib-gpu's options
// and scene as arguments, text rays, one record per ray):
//   1. the run, counting the rays the integrator asks the caster for (nearest hit and shadow,
//      per thread), then the run again without counting, timed (with a fixed seed, the same
//      rays);
//   2. the run again over every K-th sensor (-record_every K), recording those rays;
//   3. the recorded rays replayed through a fresh Embree caster on the same scene and threads,
//      one ray a call as the integrator calls it, timed;
//   then passes 1 and 3 again in turns, N times in all (-repeat N, 3), each one's fastest kept.
// Efficiency = (rays a second of the run) / (rays a second of the replay): the share of the
// run's time that is the caster's. The replay goes through dayflux's Backend (Embree's
// rtcIntersect1/rtcOccluded1 plus the hit's double-precision point and normal), the part of
// the work no integrator can avoid.
// usage: ray_replay_bench [-record_every K] [-repeat N] [-paths P] rcontrib-gpu-options... scene...
//        < sensors   (-paths: EngineOptions::cpu_paths_at_once)
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "raytrace/backend.h"
#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/run.h"
#include "replay_common.h"
#include "util/errors.h"

namespace dayflux {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

struct Counts {
    uint64_t closest = 0, occluded = 0;
};

// The rays a run traces, per thread; recorded as well when log is set.
struct RayLog {
    bool record = false;
    tbb::enumerable_thread_specific<Counts> counts;
    tbb::enumerable_thread_specific<std::vector<TraceRay>> closest, occluded, blocked;
    std::vector<uint32_t> blockers;  // the engine's, for the replay's caster

    Counts Total() const {
        Counts t;
        for (const Counts &c : counts) t.closest += c.closest, t.occluded += c.occluded;
        return t;
    }
};

// The caster, counting (and recording) what goes through it.
class LoggingBackend : public ForwardingBackend {
  public:
    LoggingBackend(std::unique_ptr<Backend> inner, RayLog *log)
        : ForwardingBackend(std::move(inner)), log_(log) {}
    void SetBlockers(std::vector<uint32_t> triangles) override {
        log_->blockers = triangles;
        inner_->SetBlockers(std::move(triangles));
    }
    void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const override {
        log_->counts.local().closest += n;
        if (log_->record) log_->closest.local().insert(log_->closest.local().end(), rays, rays + n);
        inner_->Closest(rays, hits, n);
    }
    void Occluded(const TraceRay *rays, bool *occluded, size_t n) const override {
        log_->counts.local().occluded += n;
        if (log_->record)
            log_->occluded.local().insert(log_->occluded.local().end(), rays, rays + n);
        inner_->Occluded(rays, occluded, n);
    }
    // Shadow rays tested against the blockers alone: counted with the shadow rays.
    void Blocked(const TraceRay *rays, bool *blocked, size_t n) const override {
        log_->counts.local().occluded += n;
        if (log_->record) log_->blocked.local().insert(log_->blocked.local().end(), rays, rays + n);
        inner_->Blocked(rays, blocked, n);
    }

  private:
    RayLog *log_;
};

// The run over rays (6 doubles each), timed; the engine's caster logs into *log, if any (the
// timed runs have none: the log's per-thread counters would be timed with them).
double TimedRun(const RcontribOptions &o, const FlatScene &flat, const std::vector<double> &rays,
                RayLog *log) {
    EngineOptions engine = o.engine;
    if (log)
        engine.wrap_cpu_backend = [log](std::unique_ptr<Backend> b) {
            return std::make_unique<LoggingBackend>(std::move(b), log);
        };
    const std::unique_ptr<ContribEngine> e = CreateRunEngine(o, flat, o.contrib, engine);
    const size_t n = rays.size() / 6;
    std::vector<double> records(n * 3 * static_cast<size_t>(e->Columns()), 0.0);
    const Clock::time_point start = Clock::now();
    e->Trace(rays.data(), n, 0, 0, records.data());
    return Seconds(start);
}

// The recorded rays through a fresh caster, one a call, in parallel; seconds.
double Replay(const FlatScene &flat, const RayLog &log, const std::vector<TraceRay> &closest,
              const std::vector<TraceRay> &occluded, const std::vector<TraceRay> &blocked) {
    const std::unique_ptr<Backend> caster = CreateEmbreeBackend();
    caster->SetBlockers(log.blockers);
    caster->Commit(flat);
    const Clock::time_point start = Clock::now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, closest.size(), 4096), [&](auto r) {
        TraceHit hit;
        for (size_t i = r.begin(); i < r.end(); ++i) caster->Closest(&closest[i], &hit, 1);
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, occluded.size(), 4096), [&](auto r) {
        bool blocked;
        for (size_t i = r.begin(); i < r.end(); ++i) caster->Occluded(&occluded[i], &blocked, 1);
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, blocked.size(), 4096), [&](auto r) {
        bool stopped;
        for (size_t i = r.begin(); i < r.end(); ++i) caster->Blocked(&blocked[i], &stopped, 1);
    });
    return Seconds(start);
}

int Main(int argc, char **argv) {
    std::vector<std::string> args(argv, argv + argc);
    size_t every = 1, repeat = 3, paths = EngineOptions().cpu_paths_at_once;
    bench::TakeCounts(&args, {{"-record_every", &every}, {"-repeat", &repeat}, {"-paths", &paths}});
    std::vector<std::string> header;
    RcontribOptions o = ParseRcontribOptions(args, &header);
    if (o.engine.backend != "embree") ErrorExit("the replay measures the CPU (Embree) backend");
    o.engine.cpu_paths_at_once = static_cast<int>(paths);
    const std::unique_ptr<tbb::global_control> threads = LimitThreads(o.threads);
    std::string octree_header;
    const FlatScene flat = ReadRcontribScene(o.scene, &octree_header);
    const std::vector<double> rays = bench::ReadRays(std::cin);

    // The rays are counted in a run of their own: with a fixed seed every run traces the same.
    RayLog counted;
    TimedRun(o, flat, rays, &counted);
    const Counts total = counted.Total();
    double run_s = TimedRun(o, flat, rays, nullptr);

    const std::vector<double> subset = bench::EveryKth(rays, every);
    RayLog recorded;
    recorded.record = true;
    TimedRun(o, flat, subset, &recorded);
    std::vector<TraceRay> closest, occluded, blocked;
    for (auto &v : recorded.closest) closest.insert(closest.end(), v.begin(), v.end());
    for (auto &v : recorded.occluded) occluded.insert(occluded.end(), v.begin(), v.end());
    for (auto &v : recorded.blocked) blocked.insert(blocked.end(), v.begin(), v.end());
    double replay_s = Replay(flat, recorded, closest, occluded, blocked);
    // Both again, in turns, keeping each one's fastest: the replay's rate moves by up to 40 %
    // between runs on a shared machine, and this pairs like with like.
    for (size_t k = 1; k < repeat; ++k) {
        run_s = std::min(run_s, TimedRun(o, flat, rays, nullptr));
        replay_s = std::min(replay_s, Replay(flat, recorded, closest, occluded, blocked));
    }

    const double run_rate = static_cast<double>(total.closest + total.occluded) / run_s;
    const double replay_rate =
        static_cast<double>(closest.size() + occluded.size() + blocked.size()) / replay_s;
    std::printf(
        "sensors,closest_rays,shadow_rays,run_s,run_mrays_s,replayed_rays,replay_s,"
        "replay_mrays_s,efficiency\n");
    std::printf("%zu,%llu,%llu,%.3f,%.3f,%zu,%.3f,%.3f,%.3f\n", rays.size() / 6,
                static_cast<unsigned long long>(total.closest),
                static_cast<unsigned long long>(total.occluded), run_s, run_rate * 1e-6,
                closest.size() + occluded.size() + blocked.size(), replay_s, replay_rate * 1e-6,
                run_rate / replay_rate);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
