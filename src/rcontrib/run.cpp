#include "rcontrib/run.h"

#include <tbb/global_control.h>

#include <cstdio>
#include <memory>

#include "matrix/matrices.h"
#include "raytrace/engine.h"
#include "raytrace/sensor_cache.h"
#include "raytrace/target_error.h"
#include "rcontrib/outputs.h"
#include "rcontrib/rtrace_like.h"
#include "scene/flatten.h"
#include "scene/octree.h"
#include "scene/reader.h"
#include "util/signals.h"
#include "util/strings.h"

namespace dayflux {

// The scene files and octrees, in order, flattened; the octrees' headers in *octree_header.
FlatScene ReadRcontribScene(const std::vector<std::string> &files, std::string *octree_header) {
    Scene scene;
    SceneReader reader(&scene);
    for (const std::string &s : files) {
        if (IsOctreeFile(s))
            *octree_header += ReadOctree(s, &scene).header;
        else
            reader.ReadFile(s);
    }
    return Flatten(std::move(scene));
}

void TraceToOutputs(const RcontribOptions &o, ContribEngine &engine, RcontribOutputs &outputs,
                    RaySource rays) {
    // A run stopped by a signal or an error (a full disk, a lost GPU, a bad ray) keeps the records
    // it wrote, for -r.
    try {
        const StopOnSignals stop;
        TraceRecords(o, engine, outputs, std::move(rays));
        outputs.Commit();
    } catch (const Interrupted &e) {
        const std::string kept = outputs.KeepPartial();
        throw Interrupted(e.Signal(), e.what() + (kept.empty() ? "" : "; " + kept));
    } catch (const UserError &e) {
        const std::string kept = outputs.KeepPartial();
        // A signal that also ended the program writing the rays (mid-ray: "unexpected end of
        // input") still ends this one by the signal.
        if (const int sig = StopOnSignals::Requested())
            throw Interrupted(sig, std::string("stopped by a signal (") + e.what() + ")" +
                                       (kept.empty() ? "" : "; " + kept));
        throw UserError(e.what() + (kept.empty() ? "" : "\n" + ProgramName() + ": " + kept));
    } catch (...) {
        outputs.KeepPartial();
        throw;
    }
}

std::unique_ptr<tbb::global_control> LimitThreads(int threads) {
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 threads);
}

std::unique_ptr<ContribEngine> CreateRunEngine(const RcontribOptions &o, const FlatScene &flat,
                                               const ContribOptions &contrib,
                                               const EngineOptions &engine) {
    return CreateContribEngine(
        flat, contrib, TrackedModifiers(o),
        [&o](int k) { return MakeCalContext(o, o.modifiers[k].params); }, engine);
}

void RunRcontrib(const RcontribOptions &o, const std::vector<std::string> &header_args,
                 const std::string &header_lines, RaySource rays) {
    const std::unique_ptr<tbb::global_control> threads = LimitThreads(o.threads);
    std::string header;
    const FlatScene flat = ReadRcontribScene(o.scene, &header);
    header += header_lines;
    const auto create = [&](const ContribOptions &c) {
        return CreateRunEngine(o, flat, c, o.engine);
    };
    std::unique_ptr<ContribEngine> engine;
    std::shared_ptr<TargetErrorReport> report;
    TargetErrorOptions target;
    if (o.target_error > 0) {
        target = TargetErrorOf(o);
        target.sensors = o.contrib.irradiance;
        report = std::make_shared<TargetErrorReport>();
        engine = WithTargetError(
            [&](int divisions) {
                ContribOptions c = o.contrib;
                c.ambient_divisions = divisions;
                return create(c);
            },
            target, report);
    } else {
        engine = create(o.contrib);
    }
    if (o.sensor_cache > 0 && o.contrib.ambient_bounces > 0) {
        ContribOptions direct = o.contrib;
        direct.ambient_bounces = 0;
        SensorCacheOptions c;
        c.accuracy = o.sensor_cache;
        c.resolution = o.ambient_resolution;
        c.seed = o.contrib.seed;
        engine = WithSensorCache(std::move(engine), create(direct), flat, c, o.progress);
    }
    if (report) header += "TARGET_ERROR=" + FormatNumber(o.target_error) + "\n";
    RcontribOutputs outputs(o, engine->Columns(), header_args, header, engine->Label());
    TraceToOutputs(o, *engine, outputs, std::move(rays));
    if (report) ReportTargetError(o, target, *report);
}

}  // namespace dayflux
