// rcontrib-gpu: RADIANCE's rcontrib (contribution coefficients of modifiers to input rays) on
// dayflux's engines: the CPU with Embree, or a Vulkan GPU (src/rcontrib for the command line,
// outputs and records; src/raytrace for the engines). `rcontrib-gpu -devices` lists the Vulkan
// devices the build sees.
#include <tbb/global_control.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/outputs.h"
#include "rcontrib/records.h"
#include "scene/flatten.h"
#include "scene/octree.h"
#include "scene/reader.h"
#include "util/errors.h"

namespace dayflux {
namespace {

// The scene files and octrees, in order, flattened; the octrees' headers in *octree_header.
FlatScene ReadScene(const std::vector<std::string> &files, std::string *octree_header) {
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

int Main(int argc, char **argv) {
    if (argc == 2 && std::string(argv[1]) == "-devices") {
        std::fputs(DescribeGpuDevices().c_str(), stdout);
        return 0;
    }
    std::vector<std::string> header_args = {argv[0]};
    const RcontribOptions o = ParseRcontribOptions(argc, argv, &header_args);
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, o.threads);
    std::string octree_header;
    const FlatScene flat = ReadScene(o.scene, &octree_header);
    const std::unique_ptr<ContribEngine> engine = CreateContribEngine(
        flat, o.contrib, TrackedModifiers(o),
        [&o](int k) { return MakeCalContext(o, o.modifiers[k].params); }, o.engine);
    RcontribOutputs outputs(o, engine->Columns(), header_args, octree_header, engine->Label());
    TraceRecords(o, *engine, outputs);
    outputs.Commit();
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
