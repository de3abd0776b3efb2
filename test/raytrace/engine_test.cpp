// The engine interface in-process: a scene packed once, what the GPU cannot take decided from the
// packed tables before anything is compiled, and an engine created from options tracing records.
#include "raytrace/engine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "raytrace/backend.h"
#include "raytrace/core/random.h"
#include "raytrace/materials.h"
#include "raytrace/packing.h"
#include "raytrace/runs.h"
#include "scene/reader.h"
#include "test_util.h"
#include "util/errors.h"

namespace dayflux::test {
namespace {

FlatScene SceneOf(const std::string &text) {
    Scene scene;
    SceneReader(&scene).ReadText(text, "scene.rad");
    return Flatten(std::move(scene));
}

std::vector<TrackedModifier> Tracking(const std::string &name) {
    TrackedModifier t;
    t.name = name;
    return {t};
}

std::unique_ptr<cal::Context> RayInit(int) {
    auto cx = std::make_unique<cal::Context>();
    cx->LoadRayInit();
    return cx;
}

// A room 4 x 4 x 3 m of material `wall`, open to the south above a sill 1 m high.
const char *const kRoomOfWalls =
    "wall polygon floor 0 0 12 0 0 0  0 4 0  4 4 0  4 0 0\n"
    "wall polygon ceiling 0 0 12 0 0 3  4 0 3  4 4 3  0 4 3\n"
    "wall polygon west 0 0 12 0 0 0  0 0 3  0 4 3  0 4 0\n"
    "wall polygon east 0 0 12 4 0 0  4 4 0  4 4 3  4 0 3\n"
    "wall polygon north 0 0 12 0 4 0  0 4 3  4 4 3  4 4 0\n"
    "wall polygon sill 0 0 12 0 0 0  4 0 0  4 0 1  0 0 1\n";

// -I at -ab ab, -ad ad, -lw lw and a fixed seed (the rest rcontrib's defaults).
ContribOptions Irradiance(int ab, int ad, double lw, uint64_t seed) {
    ContribOptions options;
    options.irradiance = true;
    options.ambient_bounces = ab;
    options.ambient_divisions = ad;
    options.limit_weight = lw;
    options.seed = seed;
    return options;
}

// The records of n input rays (skyglow tracked, one bin) on the engine `engine` names, or none
// where another opened (no such device: the run went to Embree).
std::vector<double> RecordsOn(const FlatScene &flat, const ContribOptions &options,
                              const EngineOptions &engine, const double *rays, size_t n) {
    const std::unique_ptr<ContribEngine> e =
        CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, engine);
    if (e->Label().rfind(engine.backend, 0) != 0) return {};
    std::vector<double> records(3 * n, 0.0);
    e->Trace(rays, n, 0, 0, records.data());
    return records;
}

// The records of n input rays on the CPU, walking `paths` cells' paths at once.
std::vector<double> RecordsWithPaths(const FlatScene &flat, const ContribOptions &options,
                                     int paths, const double *rays, size_t n) {
    EngineOptions engine_options;
    engine_options.cpu_paths_at_once = paths;
    return RecordsOn(flat, options, engine_options, rays, n);
}

// A stack of mixfuncs n deep over plastic, on a roof.
std::string NestedMixfuncs(int n) {
    std::string s = std::string(kSky) + "void plastic m0 0 0 5 .5 .5 .5 0 0\n";
    for (int i = 1; i <= n; ++i)
        s += "void mixfunc m" + std::to_string(i) + " 4 m" + std::to_string(i - 1) +
             " void .5 . 0 0\n";
    return s + "m" + std::to_string(n) + " polygon roof 0 0 12 -2 -2 1  2 -2 1  2 2 1  -2 2 1\n";
}

// The packer records what the core must compile for a scene and how deep its mixfuncs nest, and
// the GPU's limits are judged from that alone: 7 mixfunc levels fit its stack of waiting sides,
// 8 do not; nor do more than 16 specular samples.
TEST(Packing, TheGpusLimitsAreKnownBeforeCompiling) {
    ContribOptions options;
    const std::vector<TrackedModifier> tracked = Tracking("skyglow");
    for (int n : {7, 8}) {
        const FlatScene flat = SceneOf(NestedMixfuncs(n));
        const SceneMaterials table(flat, tracked);
        const PackedScene packed = PackScene(flat, table, tracked, options);
        EXPECT_EQ(packed.mix_depth, n);
        EXPECT_EQ(packed.mix_deepest, "roof");
        EXPECT_FALSE(packed.bsdf || packed.dielectric || packed.local_sources ||
                     packed.mirror_images || packed.inside);
        EXPECT_EQ(
            UnsupportedOnGpu(packed, options),
            n == 7 ? "" : "a mixfunc nested more than 7 deep (roof) is traced on the CPU only");
    }
    const FlatScene flat =
        SceneOf(std::string(kSky) +
                "void dielectric water 0 0 5 .9 .9 .9 1.33 0\n"
                "water sphere drop 0 0 4 0 0 2 .5\n"
                "void light lamp 0 0 3 1 1 1\nlamp ring disc 0 0 8 0 0 3 0 0 -1 0 .2\n");
    const SceneMaterials table(flat, tracked);
    options.specular_jitter = 20;
    const PackedScene packed = PackScene(flat, table, tracked, options);
    EXPECT_TRUE(packed.dielectric && packed.local_sources);
    EXPECT_EQ(packed.ndirect, 1);  // the lamp; the sky is a glow
    EXPECT_EQ(UnsupportedOnGpu(packed, options),
              "-ss above 16 (more specular samples than the GPU's ray stack holds)");
}

// An engine made from options traces records in-process: an upward sensor under a uniform sky
// gets pi from every replica (every sample reaches the sky), so -se's variance is nought, and
// the same seed gives the same record twice.
TEST(Engine, TracesRecordsInProcess) {
    const FlatScene flat = SceneOf(kSky);
    ContribOptions options;
    options.irradiance = true;
    options.ambient_divisions = 256;
    const std::unique_ptr<ContribEngine> engine =
        CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, EngineOptions{});
    ASSERT_EQ(engine->Columns(), 1);
    EXPECT_EQ(engine->Label(), "embree");
    const double rays[12] = {0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 2};
    std::vector<double> sums(6, 0.0), variances(6, 0.0);
    TraceReplicas(*engine, rays, 2, 0, 8, sums.data(), variances.data());
    for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(sums[i], M_PI, 1e-12) << i;
        EXPECT_NEAR(variances[i], 0, 1e-20) << i;
    }
    std::vector<double> again(6, 0.0);
    engine->Trace(rays, 2, 0, 0, again.data());
    engine->Trace(rays, 2, 0, 0, again.data());
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(again[i], 2 * M_PI, 1e-12);
}

// TraceKeyed: rays scattered over a run (the sensor cache's records) each draw the numbers they
// draw in the whole run, on the CPU (runs of consecutive keys) and on a GPU (one dispatch, the
// keys as offsets in the rays' buffer): a sky half covered, aslant, makes each record depend
// on them.
// A sky half covered, aslant, seen with -I -ab 1 -ad 16 from eight points in a row (the rays:
// origin, direction). The engine holds the scene: it must outlive the engine.
struct HalfCoveredSky {
    FlatScene flat = SceneOf(std::string(kSky) +
                             "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
                             "grey polygon roof 0 0 12 .3 -9 1  9 -9 1  9 9 1  -2 9 1\n");
    std::vector<double> rays;
    HalfCoveredSky() {
        for (size_t i = 0; i < 8; ++i) rays.insert(rays.end(), {0.1 * double(i), 0, 0, 0, 0, 1});
    }
    std::unique_ptr<ContribEngine> Engine(const EngineOptions &engine_options,
                                          int divisions = 16) const {
        ContribOptions options;
        options.irradiance = true;
        options.ambient_bounces = 1;
        options.ambient_divisions = divisions;
        return CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, engine_options);
    }
    // Engine(), or null with why where engine_options.backend was not what opened (no device).
    std::unique_ptr<ContribEngine> EngineOn(const EngineOptions &engine_options,
                                            std::string *why) const {
        std::unique_ptr<ContribEngine> engine = Engine(engine_options);
        if (engine->Label().rfind(engine_options.backend, 0) == 0) return engine;
        *why = "no " + engine_options.backend + " engine: " + engine->Label();
        return nullptr;
    }
    size_t Rays() const { return rays.size() / 6; }
};

// The scene and its engine on a backend (null, with why, where that backend did not open).
struct HalfCoveredSkyOn {
    HalfCoveredSky scene;
    std::string why;
    std::unique_ptr<ContribEngine> engine;
    explicit HalfCoveredSkyOn(const EngineOptions &o) : engine(scene.EngineOn(o, &why)) {}
};

void ExpectKeyedAsInRun(const EngineOptions &engine_options) {
    const HalfCoveredSkyOn on(engine_options);
    if (!on.engine) GTEST_SKIP() << on.why;
    ContribEngine *engine = on.engine.get();
    const std::vector<double> &rays = on.scene.rays;
    const size_t n = on.scene.Rays();
    std::vector<double> whole(3 * n, 0.0);
    engine->Trace(rays.data(), n, 100, 0, whole.data());
    const std::vector<uint64_t> keys = {101, 104, 105, 107};
    std::vector<double> some_rays, some(3 * keys.size(), 0.0);
    for (uint64_t k : keys)
        some_rays.insert(some_rays.end(), rays.begin() + 6 * (k - 100),
                         rays.begin() + 6 * (k - 99));
    engine->TraceKeyed(some_rays.data(), keys.size(), keys.data(), 0, some.data());
    for (size_t j = 0; j < keys.size(); ++j)
        EXPECT_EQ(some[3 * j], whole[3 * (keys[j] - 100)]) << "key " << keys[j];
    // and the numbers do matter: ray 4 traced as ray 5 gets another answer
    std::vector<double> other(3, 0.0);
    const uint64_t key5 = 105;
    engine->TraceKeyed(rays.data() + 6 * 4, 1, &key5, 0, other.data());
    EXPECT_NE(other[0], whole[3 * 4]);
    EXPECT_GT(whole[0], 0.05);  // some sky seen, and some not
    EXPECT_LT(whole[0], M_PI - 0.5);
}

// TraceSlices (-target_error): each ray's slices of rows, kept apart, add up to the record of the
// whole hemisphere (the same numbers: the GPU's tasks replay the rows before their slice, the
// CPU traces the hemisphere whole and adds each cell's path to its slice), a slice beyond the
// rows adds nothing, and the two replicas of a pair draw numbers of their own. Under the open
// uniform sky, each of the two slices of -ad 16's 4 rows holds half the hemisphere: pi / 2.
void ExpectSlicesAddUp(const EngineOptions &engine_options, double tolerance) {
    const int slices = 3;  // -ad 16: 4 rows, 2 a slice, the third slice empty
    const std::vector<uint64_t> keys = {100, 101, 102, 103, 104, 105, 106, 107};
    const HalfCoveredSkyOn on(engine_options);
    if (!on.engine) GTEST_SKIP() << on.why;
    ContribEngine *engine = on.engine.get();
    const std::vector<double> &rays = on.scene.rays;
    const size_t n = on.scene.Rays();
    for (const uint32_t replica : {0u, core::kPairedReplicas, core::kPairedReplicas + 1}) {
        std::vector<double> whole(3 * n, 0.0), apart(3 * n * slices, 0.0);
        engine->Trace(rays.data(), n, 100, int(replica), whole.data());
        ASSERT_TRUE(
            engine->TraceSlices(rays.data(), n, keys.data(), int(replica), slices, apart.data()));
        for (size_t i = 0; i < n; ++i) {
            double sum = 0;
            for (int s = 0; s < slices; ++s) sum += apart[3 * (i * slices + s)];
            EXPECT_NEAR(sum, whole[3 * i], tolerance * whole[3 * i]) << "ray " << i;
            EXPECT_EQ(apart[3 * (i * slices + 2)], 0.0) << "ray " << i;
        }
    }
    // A pair's grids turn alike: at -ad 1024 in 16 slices, each slice covers the same rows of the
    // sky in both, which differ only where a cell straddles the roof's edge, far less than two
    // replicas whose grids turn each their own way (the edge then cuts the rows elsewhere).
    const std::unique_ptr<ContribEngine> fine = on.scene.Engine(engine_options, 1024);
    const auto slices_of = [&](uint32_t replica) {
        std::vector<double> v(3 * n * 16, 0.0);
        EXPECT_TRUE(fine->TraceSlices(rays.data(), n, keys.data(), int(replica), 16, v.data()));
        return v;
    };
    const auto spread = [&](uint32_t x, uint32_t y) {
        const std::vector<double> a = slices_of(x), b = slices_of(y);
        double sum = 0;
        for (size_t k = 0; k < a.size(); k += 3) sum += (a[k] - b[k]) * (a[k] - b[k]);
        return sum;
    };
    const double paired = spread(core::kPairedReplicas, core::kPairedReplicas + 1);
    EXPECT_GT(paired, 0);  // (their cells' numbers are their own)
    EXPECT_LT(paired, 0.1 * spread(0, 1));

    const FlatScene open = SceneOf(kSky);
    ContribOptions options;
    options.irradiance = true;
    options.ambient_bounces = 1;
    options.ambient_divisions = 16;
    const std::unique_ptr<ContribEngine> sky =
        CreateContribEngine(open, options, Tracking("skyglow"), RayInit, engine_options);
    std::vector<double> halves(3 * n * slices, 0.0);
    ASSERT_TRUE(sky->TraceSlices(rays.data(), n, keys.data(), 0, slices, halves.data()));
    for (size_t i = 0; i < n; ++i)
        for (int s = 0; s < 2; ++s)
            EXPECT_NEAR(halves[3 * (i * slices + s)], M_PI / 2, 1e-5) << i << " " << s;
}

TEST(Engine, SlicesAddUpToTheWholeHemisphere) { ExpectSlicesAddUp(EngineOptions{}, 1e-12); }

// The same with the CPU's cells traced one after the other, not in packets of paths.
TEST(Engine, SlicesAddUpToTheWholeHemisphereOnePathAtATime) {
    EngineOptions one;
    one.cpu_paths_at_once = 1;
    ExpectSlicesAddUp(one, 1e-12);
}

TEST(Engine, SlicesAddUpToTheWholeHemisphereVulkan) {
    EngineOptions engine;
    engine.backend = "vulkan";
    const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
    engine.device = device && *device ? device : "llvmpipe";
    ExpectSlicesAddUp(engine, 1e-5);
}

TEST(Engine, KeyedTraceAsInTheWholeRun) { ExpectKeyedAsInRun(EngineOptions{}); }

TEST(Engine, KeyedTraceAsInTheWholeRunVulkan) {
    EngineOptions engine;
    engine.backend = "vulkan";
    const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
    engine.device = device && *device ? device : "llvmpipe";
    ExpectKeyedAsInRun(engine);
}

// The GPU's slices summed on the device give the records the host's sums of every task's record
// gave, also where a run takes several dispatches (each holding its sensors' slices whole: -I at
// -ad 16 cuts a sensor into five slices, its four rows among them; dispatches of 15 tasks, then
// 10). Double accumulators: the same sums in the same order, to the bit. Float pairs (the
// default): the device's TwoSum against the host's double sums, within 1e-12; and the device's
// own sums to the bit however the dispatches fall.
TEST(Engine, SlicesSummedOnTheDeviceAsOnTheHostVulkan) {
    const auto records = [](GpuAccum accumulators, bool on_device, int tasks_per_dispatch) {
        EngineOptions engine;
        engine.backend = "vulkan";
        const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
        engine.device = device && *device ? device : "llvmpipe";
        engine.accumulators = accumulators;
        engine.gpu_slice_sums = on_device;
        engine.gpu_tasks_per_dispatch = tasks_per_dispatch;
        const HalfCoveredSky scene;
        const std::unique_ptr<ContribEngine> e = scene.Engine(engine);
        if (e->Label().rfind("vulkan", 0) != 0) return std::vector<double>();
        std::vector<double> out(scene.rays.size() / 2, 0.0);
        e->Trace(scene.rays.data(), scene.rays.size() / 6, 0, 0, out.data());
        return out;
    };
    const std::vector<double> host = records(GpuAccum::kDouble, false, 0);
    if (host.empty()) GTEST_SKIP() << "no Vulkan engine";
    EXPECT_EQ(records(GpuAccum::kDouble, true, 0), host);
    EXPECT_EQ(records(GpuAccum::kDouble, true, 17), host);  // at most 17 tasks: 15 (3 sensors)
    EXPECT_EQ(records(GpuAccum::kDouble, false, 17), host);
    EXPECT_GT(host[0], 0.05);  // some sky seen, and some not
    EXPECT_LT(host[0], M_PI - 0.5);
    const std::vector<double> pairs = records(GpuAccum::kPair, true, 0);
    EXPECT_EQ(records(GpuAccum::kPair, true, 17), pairs);
    const std::vector<double> pairs_host = records(GpuAccum::kPair, false, 0);
    ASSERT_EQ(pairs.size(), host.size());
    ASSERT_EQ(pairs_host.size(), host.size());
    for (size_t i = 0; i < host.size(); ++i) {
        EXPECT_NEAR(pairs[i], pairs_host[i], 1e-12 * std::fabs(host[i])) << i;
        EXPECT_NEAR(pairs[i], host[i], 1e-6 * std::fabs(host[i])) << i;  // float's rounding
    }
}

// The caster of an engine, counting its nearest-hit queries and their hits.
class HitCounter : public ForwardingBackend {
  public:
    HitCounter(std::unique_ptr<Backend> inner, std::atomic<size_t> *rays, std::atomic<size_t> *hits)
        : ForwardingBackend(std::move(inner)), rays_(rays), hits_(hits) {}
    void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const override {
        inner_->Closest(rays, hits, n);
        *rays_ += n;
        for (size_t i = 0; i < n; ++i) *hits_ += hits[i].hit;
    }

  private:
    std::atomic<size_t> *rays_, *hits_;
};

// The half-covered sky with a wall facing -x at x = .5 beside the sensors (x from 0 to .7),
// which many of their rays meet closer than 1.
struct WalledSky : HalfCoveredSky {
    WalledSky() {
        flat = SceneOf(std::string(kSky) +
                       "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
                       "grey polygon roof 0 0 12 .3 -9 1  9 -9 1  9 9 1  -2 9 1\n"
                       "grey polygon wall 0 0 12 .5 -9 -1  .5 -9 9  .5 9 9  .5 9 -1\n");
    }
};

// What bench/gpu_replay_bench.cpp measures GPU efficiency with: the GPU counts the nearest-hit
// queries it traces, as many as Embree's engine asks (one estimator: at -ab 1 under a sky of
// glow, one a first-hemisphere cell), logs them, and its replay kernel finds their hits again,
// as many as Embree found (float traversal apart: within 1 %; hits on the wall closer than 1
// once read as misses); the device times its stages.
TEST(Engine, RaysCountedLoggedAndReplayedVulkan) {
    const WalledSky scene;
    std::atomic<size_t> cpu_rays{0}, cpu_hits{0};
    EngineOptions cpu;
    cpu.wrap_cpu_backend = [&](std::unique_ptr<Backend> b) {
        return std::make_unique<HitCounter>(std::move(b), &cpu_rays, &cpu_hits);
    };
    std::vector<double> out(scene.rays.size() / 2, 0.0);
    scene.Engine(cpu, 1024)->Trace(scene.rays.data(), scene.Rays(), 0, 0, out.data());
    EXPECT_EQ(cpu_rays, scene.Rays() * 1024);  // 32 x 32 cells a sensor
    EngineOptions gpu;
    gpu.backend = "vulkan";
    const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
    gpu.device = device && *device ? device : "llvmpipe";
    gpu.gpu_ray_log = 1 << 20;
    const std::unique_ptr<ContribEngine> e = scene.Engine(gpu, 1024);
    if (e->Label().rfind("vulkan", 0) != 0) GTEST_SKIP() << "no Vulkan engine";
    EXPECT_EQ(e->RaysTraced(), 0u);
    e->Trace(scene.rays.data(), scene.Rays(), 0, 0, out.data());
    EXPECT_EQ(e->RaysTraced(), cpu_rays);
    const ContribEngine::ReplayResult replay = e->ReplayLoggedRays(2);
    EXPECT_EQ(replay.rays, cpu_rays);
    EXPECT_GT(cpu_hits, cpu_rays / 10);  // the roof: some hit, others reach the sky
    EXPECT_LT(cpu_hits, cpu_rays * 9 / 10);
    EXPECT_NEAR(double(replay.hits), double(cpu_hits), 0.01 * double(cpu_hits));
    EXPECT_GT(replay.wall_seconds, 0);
    const std::vector<double> stages = e->StageSeconds();
    if (!stages.empty()) {  // where the queue has timestamps (lavapipe's has)
        EXPECT_GT(stages[0], 0);
        EXPECT_GT(replay.device_seconds, 0);
    }
}

// The caster of an engine, counting the shadow rays the blockers stopped; with drop_blockers,
// given none (every shadow ray then walks through what it meets).
class BlockerCounter : public ForwardingBackend {
  public:
    BlockerCounter(std::unique_ptr<Backend> inner, bool drop_blockers, size_t *blockers,
                   std::atomic<size_t> *stopped)
        : ForwardingBackend(std::move(inner)),
          drop_(drop_blockers),
          blockers_(blockers),
          stopped_(stopped) {}
    void SetBlockers(std::vector<uint32_t> triangles) override {
        *blockers_ = triangles.size();
        if (!drop_) inner_->SetBlockers(std::move(triangles));
    }
    void Blocked(const TraceRay *rays, bool *blocked, size_t n) const override {
        inner_->Blocked(rays, blocked, n);
        *stopped_ += static_cast<size_t>(std::count(blocked, blocked + n, true));
    }

  private:
    bool drop_;
    size_t *blockers_;
    std::atomic<size_t> *stopped_;
};

// A room lit by five suns through a glass window and a trans partition, at two bounces: the
// shadow rays that an opaque surface stops are answered by the blockers alone (plastic walls,
// a black box; not the glass, the trans, or the tracked sky), and every record is what the
// walk through each surface gives.
TEST(Engine, ShadowRaysStoppedByBlockersAsByTheWalk) {
    std::string text =
        "void plastic wall 0 0 5 .5 .5 .5 0 0\n"
        "void glass pane 0 0 3 .8 .8 .8\n"
        "void trans veil 0 0 7 .6 .6 .6 0 0 .5 .6\n"
        "void plastic box 0 0 5 0 0 0 0 0\n" +
        std::string(kRoomOfWalls) +
        "pane polygon window 0 0 12 0 0 1  4 0 1  4 0 3  0 0 3\n"
        "veil polygon partition 0 0 12 2 0 0  2 2 0  2 2 3  2 0 3\n"
        "box polygon lid 0 0 12 .5 1 .5  1 1 .5  1 1.5 .5  .5 1.5 .5\n"
        // a tilted shelf that the fifth sun grazes (0.2 degrees): its shadow rays must not meet
        // the shelf they leave, which float rounding puts a hair off their origin
        "wall polygon shelf 0 0 12 2.029286 2.323138 1.798902  2.757514 1.637802 1.798902  "
        "3.170714 2.076862 1.001098  2.442486 2.762198 1.001098\n";
    const double suns[5][3] = {{0, -.8, .6},
                               {.5, -.7, .5},
                               {-.4, -.9, .2},
                               {.3, -.3, .9},
                               {0.249377, -0.798007, 0.548630}};
    std::vector<TrackedModifier> tracked;
    for (int k = 0; k < 5; ++k) {
        const std::string name = "solar" + std::to_string(k + 1);
        char dir[96];
        std::snprintf(dir, sizeof dir, "%g %g %g", suns[k][0], suns[k][1], suns[k][2]);
        text += "void light " + name + " 0 0 3 1000 1000 1000\n" + name + " source sun" +
                std::to_string(k + 1) + " 0 0 4 " + dir + " 0.533\n";
        TrackedModifier t;
        t.name = name;
        t.first_column = k;
        tracked.push_back(t);
    }
    const FlatScene flat = SceneOf(text);
    ContribOptions options = Irradiance(2, 64, 1e-4, 3);
    options.source_jitter = 0;
    std::vector<double> rays;
    // (off the lines through the window's corners along the suns: there the walk and the
    // blockers may settle a ray meeting two surfaces at once either way)
    for (double x : {.31, 1.23, 2.47, 3.53})
        for (double y : {.52, 2.04, 3.46}) rays.insert(rays.end(), {x, y, .8, 0, 0, 1});
    const size_t n = rays.size() / 6;
    std::vector<double> records[2];
    size_t blockers[2] = {0, 0};
    std::atomic<size_t> stopped[2];
    for (int drop = 0; drop < 2; ++drop) {
        stopped[drop] = 0;
        EngineOptions engine_options;
        engine_options.wrap_cpu_backend = [&, drop](std::unique_ptr<Backend> b) {
            return std::make_unique<BlockerCounter>(std::move(b), drop == 1, &blockers[drop],
                                                    &stopped[drop]);
        };
        const std::unique_ptr<ContribEngine> engine =
            CreateContribEngine(flat, options, tracked, RayInit, engine_options);
        ASSERT_EQ(engine->Columns(), 5);
        records[drop].assign(3 * 5 * n, 0.0);
        engine->Trace(rays.data(), n, 0, 0, records[drop].data());
    }
    // floor, ceiling, the three walls, the sill, the lid and the shelf: two triangles each
    EXPECT_EQ(blockers[0], 16u);
    EXPECT_GT(stopped[0], 1000u);
    EXPECT_EQ(stopped[1], 0u);
    double most = 0;
    for (size_t i = 0; i < records[0].size(); ++i) {
        EXPECT_NEAR(records[0][i], records[1][i], 1e-12 + 1e-9 * std::abs(records[1][i])) << i;
        most = std::max(most, records[1][i]);
    }
    // direct sun through the glass: a coefficient of 6.8e-5 sr x cos x T (cos .9, T .5 at least)
    EXPECT_GT(most, 3e-5);
}

// A thread walks several cells' paths of a sensor's first hemisphere at once (their rays traced
// in packets): each path draws the numbers it draws one after the other, so the records agree to
// the rounding of their sums' order, for the plain estimator, -asub's, and the full one (a local
// source, glass), through polygons and an analytic sphere, with packets full and partly full.
class CellPaths : public ::testing::TestWithParam<int> {};

// The room of walls with a trans partition and a ball, at -I -ab 3 -ad 100; with -asub 2
// (subsampled), or also glass in its window and a lamp (full); 13 sensors, one aslant.
struct CellPathsRoom {
    FlatScene flat;
    ContribOptions options = Irradiance(3, 100, 1e-4, 5);
    std::vector<double> rays;
    CellPathsRoom(bool subsampled, bool full) {
        std::string text = std::string(kSky) +
                           "void plastic wall 0 0 5 .6 .6 .6 0 0\n"
                           "void trans veil 0 0 7 .6 .6 .6 0 0 .5 .6\n" +
                           kRoomOfWalls +
                           "veil polygon partition 0 0 12 2 1 0  2 3 0  2 3 2  2 1 2\n"
                           "wall sphere ball 0 0 4 3 2.5 .8 .4\n";
        if (subsampled) options.ambient_subsamples = 2;
        if (full)
            text +=
                "void glass pane 0 0 3 .8 .8 .8\n"
                "pane polygon window 0 0 12 0 0 1  4 0 1  4 0 3  0 0 3\n"
                "void light bulb 0 0 3 50 50 50\n"
                "bulb sphere lamp 0 0 4 1 3 2.5 .1\n";
        flat = SceneOf(text);
        for (double x : {.5, 1.5, 2.5, 3.5})
            for (double y : {.5, 2.2, 3.5}) rays.insert(rays.end(), {x, y, .8, 0, 0, 1});
        rays.insert(rays.end(), {1.2, 1.9, 1.4, 0.6, 0, 0.8});  // aslant, toward the window
    }
    size_t Rays() const { return rays.size() / 6; }
};

TEST_P(CellPaths, AtOnceAsOneAfterTheOther) {
    const int variant = GetParam();
    const CellPathsRoom room(variant == 1, variant == 2);
    const FlatScene &flat = room.flat;
    const ContribOptions &options = room.options;
    const std::vector<double> &rays = room.rays;
    const size_t n = room.Rays();
    std::vector<double> records[4];
    const int paths[4] = {1, 3, 8, 16};
    for (int k = 0; k < 4; ++k)
        records[k] = RecordsWithPaths(flat, options, paths[k], rays.data(), n);
    for (int k = 1; k < 4; ++k)
        for (size_t i = 0; i < 3 * n; ++i)
            EXPECT_NEAR(records[k][i], records[0][i], 1e-12 + 1e-12 * std::abs(records[0][i]))
                << paths[k] << " paths, value " << i;
    for (size_t i = 0; i < n; ++i) EXPECT_GT(records[0][3 * i], 0.1) << i;  // light reaches each
}

// A cell's path that fills the ray stack drops what it drops one after the other: there the
// first hemisphere's item holds the bottom slot under every cell's path but the last (a rough
// metal floor, -ss 20000, -lw 1e-9: each specular sample pushes thousands of rays).
TEST(Engine, CellPathsFillTheStackAsOneAfterTheOther) {
    const FlatScene flat = SceneOf(std::string(kSky) +
                                   "void metal rough 0 0 5 .8 .8 .8 .9 .2\n"
                                   "rough polygon floor 0 0 12 -100 -100 0  100 -100 0  100 100 0"
                                   "  -100 100 0\n");
    ContribOptions options = Irradiance(1, 4, 1e-9, 5);
    options.specular_jitter = 20000;
    const double ray[6] = {0, 0, .5, 0, 0, -1};
    const std::vector<double> records[2] = {RecordsWithPaths(flat, options, 1, ray, 1),
                                            RecordsWithPaths(flat, options, 8, ray, 1)};
    // (the stack overflows: 46,451 rays dropped, which the engine warns once a process; with a
    // lane's path given the whole stack, the three cells before the last kept one more ray
    // each: 1.1e-4 more)
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(records[1][i], records[0][i], 1e-12 + 1e-12 * std::abs(records[0][i])) << i;
}

std::string EstimatorName(const ::testing::TestParamInfo<int> &info) {
    const char *const names[3] = {"Plain", "Subsampled", "Full"};
    return names[info.param];
}
INSTANTIATE_TEST_SUITE_P(Engine, CellPaths, ::testing::Values(0, 1, 2), EstimatorName);

EngineOptions OnVulkan(GpuEngine gpu_engine) {
    EngineOptions engine;
    engine.backend = "vulkan";
    const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
    engine.device = device && *device ? device : "llvmpipe";
    engine.gpu_engine = gpu_engine;
    return engine;
}

// The GPU's paths engine (one invocation a first-hemisphere cell's path, records in fixed point)
// gives Embree's records, to float rounding, on the room whose cells' paths pass a trans
// partition and meet a sphere, at -ab 3; and the same bytes however its dispatches fall (tasks
// of 5: sensors cut between dispatches, fewer walkers; or 1 MiB of device memory) and run
// after run, since its sums are exact. (Against the tasks engine to 1e-6:
// PathsEngineScalesContributionsVulkan.)
TEST(Engine, PathsEngineAsEmbreeVulkan) {
    CellPathsRoom room(false, false);
    const size_t n = room.Rays();
    const auto records = [&](const EngineOptions &engine) {
        return RecordsOn(room.flat, room.options, engine, room.rays.data(), n);
    };
    const std::vector<double> paths = records(OnVulkan(GpuEngine::kPaths));
    if (paths.empty()) GTEST_SKIP() << "no Vulkan engine";
    const std::vector<double> cpu = records(EngineOptions{});
    ASSERT_EQ(paths.size(), cpu.size());
    for (size_t i = 0; i < cpu.size(); ++i) {
        EXPECT_NEAR(paths[i], cpu[i], 1e-5 * std::abs(cpu[i])) << i;  // (here 5e-8 at most)
        if (i % 3 == 0) {
            EXPECT_GT(paths[i], 0.1) << i;  // light reaches each sensor
        }
    }
    EngineOptions small_dispatches = OnVulkan(GpuEngine::kPaths);
    small_dispatches.gpu_tasks_per_dispatch = 5;
    EXPECT_EQ(records(small_dispatches), paths);
    EXPECT_EQ(records(OnVulkan(GpuEngine::kPaths)), paths);
    // (a benchmark's budget of device memory: fewer cells a dispatch, the same sums)
    EngineOptions tight_memory = OnVulkan(GpuEngine::kPaths);
    tight_memory.gpu_scratch_bytes = uint64_t(1) << 20;
    EXPECT_EQ(records(tight_memory), paths);
}

// The paths engine's records keep the numbers' keys (TraceKeyed) and its slices apart add up
// (TraceSlices, -target_error's), as the tasks engine's do.
TEST(Engine, KeyedTraceAsInTheWholeRunPathsVulkan) {
    ExpectKeyedAsInRun(OnVulkan(GpuEngine::kPaths));
}
TEST(Engine, SlicesAddUpToTheWholeHemispherePathsVulkan) {
    ExpectSlicesAddUp(OnVulkan(GpuEngine::kPaths), 1e-5);
}

// -V+ contributions: the paths engine's fixed point scaled by the tracked sources' radiance
// (a sky glow of 3000: units of 2^-36), its records the tasks engine's, negative ones too; where
// a pattern on the tracked glow leaves that unknown, the run goes to the tasks engine, and so
// does one whose radiances lie more than 2^16 apart.
TEST(Engine, PathsEngineScalesContributionsVulkan) {
    ContribOptions options = Irradiance(1, 16, 1e-4, 1);
    options.contributions = true;
    const HalfCoveredSky scene;
    const auto run = [&](const std::string &sky, GpuEngine gpu_engine, std::vector<double> *out) {
        const FlatScene flat = SceneOf(sky +
                                       "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
                                       "grey polygon roof 0 0 12 .3 -9 1  9 -9 1  9 9 1"
                                       "  -2 9 1\n");
        const std::unique_ptr<ContribEngine> e =
            CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, OnVulkan(gpu_engine));
        out->assign(scene.rays.size() / 2, 0.0);
        e->Trace(scene.rays.data(), scene.Rays(), 0, 0, out->data());
        return e->Label();
    };
    const std::string bright =
        "void glow skyglow 0 0 4 3000 3000 3000 0\n"
        "skyglow source sky 0 0 4 0 0 1 180\n";
    std::vector<double> tasks, paths;
    if (run(bright, GpuEngine::kTasks, &tasks).rfind("vulkan: ", 0) != 0)
        GTEST_SKIP() << "no Vulkan engine";
    EXPECT_EQ(run(bright, GpuEngine::kPaths, &paths).rfind("vulkan paths: ", 0), 0u);
    for (size_t i = 0; i < tasks.size(); ++i)
        EXPECT_NEAR(paths[i], tasks[i], 1e-9 + 1e-6 * tasks[i]) << i;
    EXPECT_GT(tasks[0], 0.05 * 3000);  // some sky seen, and some not
    EXPECT_LT(tasks[0], (M_PI - 0.5) * 3000);
    // A sky of negative radiance: every add negative (two's complement in the fixed point), each
    // rounded as its magnitude is, so the records are exactly the negated ones.
    std::vector<double> negative;
    run("void glow skyglow 0 0 4 -3000 -3000 -3000 0\nskyglow source sky 0 0 4 0 0 1 180\n",
        GpuEngine::kPaths, &negative);
    for (size_t i = 0; i < paths.size(); ++i) EXPECT_EQ(negative[i], -paths[i]) << i;
    const std::string patterned =
        "void brightfunc dim 2 Dz . 0 0\n"
        "dim glow skyglow 0 0 4 3000 3000 3000 0\n"
        "skyglow source sky 0 0 4 0 0 1 180\n";
    const std::string label = run(patterned, GpuEngine::kPaths, &paths);
    EXPECT_EQ(label.rfind("vulkan: ", 0), 0u) << label;
    // so does one whose radiances lie more than 2^16 apart (one scale serves them all)
    const std::string spread =
        "void glow skyglow 0 0 4 3000 3000 .001 0\nskyglow source sky 0 0 4 0 0 1 180\n";
    EXPECT_EQ(run(spread, GpuEngine::kPaths, &paths).rfind("vulkan: ", 0), 0u);
    EXPECT_EQ(run(bright, GpuEngine::kPaths, &paths).rfind("vulkan paths: ", 0), 0u);
}

// A sum the paths engine's fixed point cannot hold (2^63 units: 32768 in coefficients) is an
// error, not a wrapped number: a sensor facing a floor whose pattern multiplies what it reflects,
// under a sky of coefficient 1, gets pi x .9 x the factor (every cell sees the floor, the floor's
// every cell the sky): 28,274 with 10^4, within range, the tasks engine's; 56,549 with 2 x 10^4.
TEST(Engine, PathsEngineRefusesASumBeyondItsFixedPointVulkan) {
    const ContribOptions options = Irradiance(2, 16, 1e-4, 1);
    const auto run = [&](const char *factor, GpuEngine gpu_engine, int tasks_per_dispatch = 0) {
        const FlatScene flat =
            SceneOf(std::string(kSky) + "void brightfunc loud 2 A1 . 0 1 " + factor +
                    "\nloud plastic grey 0 0 5 .9 .9 .9 0 0\n"
                    "grey polygon floor 0 0 12 -1e4 -1e4 0  1e4 -1e4 0  1e4 1e4 0"
                    "  -1e4 1e4 0\n");
        EngineOptions engine = OnVulkan(gpu_engine);
        engine.gpu_tasks_per_dispatch = tasks_per_dispatch;
        const double ray[6] = {0, 0, .5, 0, 0, -1};
        return RecordsOn(flat, options, engine, ray, 1);
    };
    const std::vector<double> tasks = run("1e4", GpuEngine::kTasks);
    if (tasks.empty()) GTEST_SKIP() << "no Vulkan engine";
    EXPECT_NEAR(tasks[0], M_PI * .9e4, 1e-3 * M_PI * .9e4);
    const std::vector<double> paths = run("1e4", GpuEngine::kPaths);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(paths[i], tasks[i], 1e-6 * tasks[i]) << i;
    EXPECT_NEAR(run("2e4", GpuEngine::kTasks)[0], 2 * tasks[0], 1e-6 * tasks[0]);
    EXPECT_THROW(run("2e4", GpuEngine::kPaths), UserError);
    // a task a dispatch: the sensor's slices summed on the host, each within range, the sum not
    EXPECT_EQ(run("1e4", GpuEngine::kPaths, 1), paths);
    EXPECT_THROW(run("2e4", GpuEngine::kPaths, 1), UserError);
}

// The paths engine's waves (-gpu_waves): however many steps its walkers take as waves (a
// dispatch taking each walker to its next ray, one finding those rays' hits) before the walk to
// the end, the same sums as the walk alone, here over paths of up to three bounces between a
// roof and a floor. The walkers' stacks stay in storage buffers between the dispatches (where
// lavapipe otherwise keeps private arrays: waves put them there, and -gpu_scratch off is
// refused).
TEST(Engine, PathsEngineWavesGiveTheWalksSumsVulkan) {
    const HalfCoveredSky sensors;
    const FlatScene flat = SceneOf(std::string(kSky) +
                                   "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
                                   "grey polygon roof 0 0 12 .3 -9 1  9 -9 1  9 9 1  -2 9 1\n"
                                   "grey polygon floor 0 0 12 -9 -9 -.1  -9 9 -.1  9 9 -.1"
                                   "  9 -9 -.1\n");
    const ContribOptions options = Irradiance(3, 16, 1e-4, 1);
    const auto records = [&](int waves, GpuScratch scratch) {
        EngineOptions engine = OnVulkan(GpuEngine::kPaths);
        engine.gpu_waves = waves;
        engine.scratch = scratch;
        return RecordsOn(flat, options, engine, sensors.rays.data(), sensors.Rays());
    };
    // (the walk alone in storage buffers too: one shader to compile)
    const std::vector<double> walk = records(0, GpuScratch::kOn);
    if (walk.empty()) GTEST_SKIP() << "no Vulkan engine";
    EXPECT_GT(walk[0], 0.1);
    EngineOptions one_wave = OnVulkan(GpuEngine::kPaths);
    one_wave.gpu_waves = 1;  // (the paths engine's, not the tasks engine's, which has none)
    EXPECT_EQ(CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, one_wave)
                  ->Label()
                  .rfind("vulkan paths", 0),
              0u);
    for (int waves : {1, 4, 40}) EXPECT_EQ(records(waves, GpuScratch::kAuto), walk) << waves;
    EXPECT_THROW(records(1, GpuScratch::kOff), UserError);
}

// An engine the options name that does not exist is an error, not a silent choice.
TEST(Engine, UnknownBackendIsAnError) {
    EngineOptions engine;
    engine.backend = "cuda";
    EXPECT_THROW(
        CreateContribEngine(SceneOf(kSky), ContribOptions{}, Tracking("skyglow"), RayInit, engine),
        UserError);
}

}  // namespace
}  // namespace dayflux::test
