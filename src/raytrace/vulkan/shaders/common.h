// The GPU driver's bindings and dispatch record, shared by the C++ host (src/raytrace/vulkan) and
// contrib.comp. The scene's tables these bind are raytrace/core/tables.h's.
#ifndef DAYFLUX_SHADERS_COMMON_H
#define DAYFLUX_SHADERS_COMMON_H

#include "raytrace/core/language.h"
#include "raytrace/core/parameters.h"

#ifdef __cplusplus
namespace dayflux::core {
#endif

// Set 0 bindings. Binding 0 is the scene: the acceleration structure with ray queries, else our
// own BVH's nodes (PackedBvhNode), with its primitive list at kBindingBvhPrims (GpuDevice::Run).
CONST int kBindingScene = 0;
CONST int kBindingRays = 1;       // vec4 org (xyz, recentred), vec4 dir (w: key offset)
CONST int kBindingPositions = 2;  // float xyz per vertex, recentred
CONST int kBindingIndices = 3;    // uint, 3 per triangle
CONST int kBindingTriangles = 4;  // PackedTriangle per triangle
CONST int kBindingSurfaces = 5;   // PackedSurface per surface kind
CONST int kBindingSources = 6;    // PackedSource per source
CONST int kBindingAccum = 7;      // double (or float), tasks x columns x 3
CONST int kBindingTasks = 8;      // GpuTasks: what this dispatch does
// uint: stack items dropped (should stay 0), kReport* flags, nearest-hit queries traced (low
// word), rays logged (DAYFLUX_RAY_LOG), nearest-hit queries (high word)
CONST int kBindingStats = 9;
CONST int kBindingShapes = 10;    // PackedShape per analytic surface (procedural boxes)
CONST int kBindingBvhPrims = 11;  // PackedBvhEntry per leaf entry, in leaf order
CONST int kBindingKlems = 12;     // float: the BSDF materials' Klems data
CONST int kBindingRelays = 13;    // vec4: the mirrors that relay sources (PackedSource.relay)
CONST int kBindingTracked = 14;   // ivec4 per tracked modifier (tables.h's kTracked*)
// Scratch, on the device only: per task of the dispatch, its ray stack (STACK_SIZE + 1 items)
// and its hemispheres' rows (2 maxn + DEEP_LEVELS 2 DEEP_N), in storage buffers rather than
// private arrays, which NVIDIA's driver limits to about 16 KiB an invocation.
CONST int kBindingScratchItems = 15;  // Item (raytrace/core/rays.inl)
CONST int kBindingScratchRows = 16;   // vec4 (xyz: a direction)
CONST int kBindingReceivers = 17;     // vec4: what -asub samples directly (tables.h's receivers)
// The slices' records summed on the device (contrib_shader.h's CompileSliceSumShader): double, the
// dispatch's rays x columns x 3; kBindingAccum is then scratch that this stage reads.
CONST int kBindingSliceSums = 18;
CONST int kBindingParameters = 19;  // GpuParameters (core/parameters.h): the run's, `params`
// For benchmarks: 2 uvec4 a ray (org's float bits, from; dir's float bits): the rays a run logs
// (DAYFLUX_RAY_LOG, up to tasks.log_capacity), or those a replay traces (DAYFLUX_REPLAY).
CONST int kBindingRayLog = 20;
// The paths engine (EngineOptions::gpu_engine, contrib.comp's DAYFLUX_PATHS), on the device
// only: up to path_capacity PathStarts (a first-hemisphere cell's ray, the random state its path
// goes on from, the task that made it), and how many the dispatch's tasks made (a uint, zeroed).
CONST int kBindingPathStarts = 21;
CONST int kBindingPathCount = 22;
// The paths engine's walkers between the dispatches of its waves (contrib.comp's Walker), zeroed
// at the start of a run.
CONST int kBindingWalkers = 23;
// uint: each wave's count of walkers stopped at a ray (tasks.waves of them, zeroed), then the
// walkers of the last two waves, in the order they stopped: the wave's hits' dispatch and the
// next wave's rays' take them packed.
CONST int kBindingWaveQueue = 24;
CONST int kBindingCount = 25;
// The paths engine's records in fixed point: an entry counts units of 2^-kPathFixedBits (3.6e-15,
// so that an add below 1.8e-15 is lost), up to 2^63 of them (32768); a single add at most 2^61
// (8192), so that sums of a few do not wrap (a sum that passes 2^63 is caught: kReportFixedSum).
// -V+ runs scale these by their sources' radiance.
CONST int kPathFixedBits = 48;

// One dispatch: tasks [task_offset, task_offset + count) of rays x slices; a slice traces a
// share of the rows of the first hemisphere (the rest of a path follows the cell that started
// it). Results: count x columns x 3 accumulators (the paths engine: count / tasks_per_record
// records, each entry a 64-bit fixed-point number as two uints, low word first). What the core
// reads of the run is in the parameters (kBindingParameters); these are the driver's own.
struct GpuTasks {
    int rays;          // input rays in the batch (the rays buffer)
    int slices;        // tasks per ray
    int first_ray;     // index of the batch's first ray in the whole input (random numbers)
    int replica;       // -se replica (random numbers)
    int task_offset;   // first task of this dispatch
    int count;         // tasks in this dispatch
    int ncols;         // columns of a record (all tracked modifiers' bins)
    int maxn;          // first-hemisphere cells a side the rows hold: at least any -ad gives
    float tmin;        // the ray start offset
    int log_capacity;  // rays kBindingRayLog holds (DAYFLUX_RAY_LOG)
    // The paths engine: the cells the dispatch's tasks may start (kBindingPathStarts), and the
    // tasks whose paths add to one record (slices, or 1 where each slice has a record of its
    // own: TraceSlices, or a dispatch cutting a ray's slices).
    int path_capacity;
    int tasks_per_record;
    // and its fixed point's units a unit of the records (2^kPathFixedBits, or less for -V+ runs
    // whose sources' radiance is above 1: a power of 2)
    float path_scale;
    int waves;  // the paths engine's waves (EngineOptions::gpu_waves; kBindingWaveQueue)
};

#ifdef __cplusplus
}  // namespace dayflux::core
#endif
#endif  // DAYFLUX_SHADERS_COMMON_H
