// The CPU driver of the estimator core: Embree finds the hits, the calcomp interpreter evaluates
// bins and patterns, and TBB spreads input rays over threads, each with its own copy of the
// core's state (raytrace/core, compiled here in double).
#pragma once

#include <memory>
#include <vector>

#include "raytrace/engine.h"
#include "raytrace/materials.h"
#include "raytrace/packing.h"

namespace dayflux {

// An engine tracing scene on the CPU with backend (Embree, uncommitted). It keeps table (whose
// patterns packed names) and packed. paths_at_once: EngineOptions::cpu_paths_at_once.
std::unique_ptr<ContribEngine> CreateCpuContribEngine(
    const FlatScene &scene, std::vector<TrackedModifier> tracked,
    std::unique_ptr<SceneMaterials> table, PackedScene packed, const ContribOptions &options,
    const MakeContext &make_context, std::unique_ptr<Backend> backend, int paths_at_once);

}  // namespace dayflux
