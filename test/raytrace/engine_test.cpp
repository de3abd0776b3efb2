// The engine interface in-process: a scene packed once, what the GPU cannot take decided from the
// packed tables before anything is compiled, and an engine created from options tracing records.
#include "raytrace/engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

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
void ExpectKeyedAsInRun(const EngineOptions &engine_options) {
    const FlatScene flat = SceneOf(std::string(kSky) +
                                   "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
                                   "grey polygon roof 0 0 12 .3 -9 1  9 -9 1  9 9 1  -2 9 1\n");
    ContribOptions options;
    options.irradiance = true;
    options.ambient_bounces = 1;
    options.ambient_divisions = 16;
    const std::unique_ptr<ContribEngine> engine =
        CreateContribEngine(flat, options, Tracking("skyglow"), RayInit, engine_options);
    if (engine->Label().rfind(engine_options.backend, 0) != 0)
        GTEST_SKIP() << "no " << engine_options.backend << " engine: " << engine->Label();
    const size_t n = 8;
    std::vector<double> rays;
    for (size_t i = 0; i < n; ++i) rays.insert(rays.end(), {0.1 * double(i), 0, 0, 0, 0, 1});
    std::vector<double> whole(3 * n, 0.0);
    engine->Trace(rays.data(), n, 100, 0, whole.data());
    const std::vector<uint64_t> keys = {101, 104, 105, 107};
    std::vector<double> some_rays, some(3 * keys.size(), 0.0);
    for (uint64_t k : keys)
        some_rays.insert(some_rays.end(), rays.begin() + 6 * (k - 100), rays.begin() + 6 * (k - 99));
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

TEST(Engine, KeyedTraceAsInTheWholeRun) { ExpectKeyedAsInRun(EngineOptions{}); }

TEST(Engine, KeyedTraceAsInTheWholeRunVulkan) {
    EngineOptions engine;
    engine.backend = "vulkan";
    const char *device = std::getenv("DAYFLUX_VULKAN_DEVICE");
    engine.device = device && *device ? device : "llvmpipe";
    ExpectKeyedAsInRun(engine);
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
