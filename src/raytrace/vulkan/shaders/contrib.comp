// rcontrib's estimator on the GPU: the driver around the estimator core (src/raytrace/core),
// which it includes. What is its own: the bindings, our BVH walk or ray queries for the nearest
// hit (Intersect), where contributions go (AddToRecord), and main(), which maps an invocation to
// its work. Two engines (EngineOptions::gpu_engine): tasks, an invocation a task (an input ray
// and a slice of its first hemisphere) traced whole into a record of its own; and paths
// (DAYFLUX_PATHS), in two phases of one pipeline (a push constant), an invocation a task making
// its sources' part and its cells' rays, then invocations walking the cells' paths, every add
// into the ray's one record, in fixed point by integer atomics.
//
// The host prepends: #version and extensions, its sizes (DEEP_N DEEP_LEVELS STACK_SIZE
// MIX_STACK LOCAL_SIZE), ACCUM_T (DAYFLUX_ACCUM_PAIR: two an entry), cal_real (the calcomp
// functions' float or double) and the DAYFLUX_* features the scene needs, compiled in;
// shaders/common.h (the bindings, GpuTasks, and the core's Parameters); the generated calcomp
// functions, EvalBin(j), which runs bin function j, and PatternRGB(k). The run's options are
// read from the parameters buffer, so that runs differing only in them share one shader.

// (the replay kernel traces logged rays alone, whichever engine logged them)
#if defined(DAYFLUX_PATHS) && defined(DAYFLUX_REPLAY)
#undef DAYFLUX_PATHS
#endif

#include "raytrace/core/tables.h"
#include "raytrace/core/random.h"
#include "raytrace/core/sampling.h"
#include "raytrace/core/shapes.h"

layout(local_size_x = LOCAL_SIZE) in;
#ifdef DAYFLUX_BVH
layout(std430, set = 0, binding = kBindingScene) readonly buffer Bvh { PackedBvhNode bvh_nodes[]; };
layout(std430, set = 0, binding = kBindingBvhPrims) readonly buffer BvhPrims {
    PackedBvhEntry bvh_prims[];
};
#else
layout(set = 0, binding = kBindingScene) uniform accelerationStructureEXT scene;
#endif
layout(std430, set = 0, binding = kBindingRays) readonly buffer Rays { vec4 rays[]; };
layout(std430, set = 0, binding = kBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = kBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = kBindingTriangles) readonly buffer Triangles { PackedTriangle triangles[]; };
layout(std430, set = 0, binding = kBindingSurfaces) readonly buffer Surfaces { PackedSurface surfaces[]; };
layout(std430, set = 0, binding = kBindingSources) readonly buffer Sources { PackedSource sources[]; };
#ifdef DAYFLUX_PATHS
layout(std430, set = 0, binding = kBindingAccum) buffer Accum { uint accum[]; };
#else
layout(std430, set = 0, binding = kBindingAccum) buffer Accum { ACCUM_T accum[]; };
#endif
layout(std430, set = 0, binding = kBindingTasks) readonly buffer Tasks { GpuTasks tasks; };
layout(std430, set = 0, binding = kBindingParameters) readonly buffer RunParameters { Parameters params; };
layout(std430, set = 0, binding = kBindingStats) buffer Stats {
    uint stats_dropped, stats_reports, stats_rays, stats_logged, stats_rays_high;
};
layout(std430, set = 0, binding = kBindingRayLog) buffer RayLog { uvec4 ray_log[]; };
layout(std430, set = 0, binding = kBindingShapes) readonly buffer Shapes { PackedShape shapes[]; };
layout(std430, set = 0, binding = kBindingRelays) readonly buffer Relays { vec4 relays[]; };
layout(std430, set = 0, binding = kBindingTracked) readonly buffer Tracked { ivec4 tracked[]; };
layout(std430, set = 0, binding = kBindingKlems) readonly buffer Klems { float klems[]; };
layout(std430, set = 0, binding = kBindingReceivers) readonly buffer Receivers { vec4 receivers[]; };

// The stack and the rows in scratch buffers, a region per task (the core's STACK, ROW0, ROWD):
// NVIDIA's driver refuses pipelines whose private arrays pass about 16 KiB an invocation. (Else,
// on CPU devices, the core's private arrays, with MAXN set by the host.)
#ifdef DAYFLUX_SCRATCH
#define MAXN tasks.maxn
layout(std430, set = 0, binding = kBindingScratchRows) buffer ScratchRows { vec4 scratch_rows[]; };
uint stack_base, rows_base;
#define DRIVER_STACK_STORAGE \
    layout(std430, set = 0, binding = kBindingScratchItems) buffer ScratchItems { \
        Item scratch_items[]; \
    };
#define STACK(i) scratch_items[stack_base + uint(i)]
#define ROW0(i) scratch_rows[rows_base + uint(i)].xyz
#define ROWD(i) scratch_rows[rows_base + uint(2 * MAXN) + uint(i)].xyz
#endif

// ---- what the core asks of its driver (raytrace/core/README.md)
cal_real BinOf(int k, int source) { return EvalBin(tracked[k][kTrackedFunction]); }

uint acc_base;  // the record adds go to: the task's (the paths engine: its ray's, or slice's)
#if defined(DAYFLUX_PATHS)
// A sensor's record gets the adds of all its cells' paths at once: 64-bit fixed point
// (kPathFixedBits, tasks.path_scale units to 1), added by two 32-bit atomics, the carry out of the low word into the high
// one. Integer sums are exact, so a record is the same bytes whatever order its adds came in.
bool fixed_range_lost, fixed_sum_lost;  // (main reports them: kReportFixedRange, kReportFixedSum)
void AddToEntry(uint at, float v) {
    float x = abs(v) * tasks.path_scale;
    if (!(x < 2305843009213693952.0)) {  // 2^61 units, or NaN: left out, reported
        fixed_range_lost = true;
        return;
    }
    // hi units of 2^32 and the rest, exactly (x has 24 bits, the rest is theirs below 2^32)
    float hi = floor(x * (1.0 / 4294967296.0));
    uint low = uint(roundEven(x - hi * 4294967296.0)), high = uint(hi);
    if (v < 0.) {  // two's complement
        low = ~low + 1u;
        high = ~high + (low == 0u ? 1u : 0u);
    }
    uint before = atomicAdd(accum[2u * at], low);
    high += before + low < before ? 1u : 0u;
    if (high == 0u) return;
    // The sum passes 2^63 units where the high word's signed add overflows (for a record whose
    // adds all have one sign, exactly then; with both, possibly a partial sum only).
    int was = int(atomicAdd(accum[2u * at + 1u], high)), now = was + int(high);
    if (int(high) > 0 ? now < was : now > was) fixed_sum_lost = true;
}
#elif defined(DAYFLUX_ACCUM_PAIR)
// Two floats an entry: the sum, and what its rounding lost (TwoSum, exact in float), summed
// beside it: double's precision without shaderFloat64.
void AddToEntry(uint at, float v) {
    precise float sum = accum[2u * at], s = sum + v, b = s - sum, lost = (sum - (s - b)) + (v - b);
    accum[2u * at] = s;
    accum[2u * at + 1u] += lost;
}
#else
void AddToEntry(uint at, float v) { accum[at] += ACCUM_T(v); }
#endif
void AddToRecord(int column, vec3 v) {
    uint at = acc_base + 3u * uint(column);
    AddToEntry(at, v.x);
    AddToEntry(at + 1u, v.y);
    AddToEntry(at + 2u, v.z);
}

// No test of shadow rays against the blockers here (direct.inl): each walks through what it
// meets.
bool Blocked(vec3 org, vec3 dir, int from, int source) { return false; }
void BlockersAhead(vec3 org, vec3 normal, int from, bool front, bool back, int first, int end) {}

#include "raytrace/core/rays.inl"
#ifdef DAYFLUX_PATHS
// A first-hemisphere cell's path, as the first phase leaves it for the second (the core's
// StartCellPath).
struct PathStart {
    Ray r;
    uint state;
    int last;
    uint task;  // the dispatch's task that made it
};
layout(std430, set = 0, binding = kBindingPathStarts) buffer PathStarts { PathStart path_starts[]; };
layout(std430, set = 0, binding = kBindingPathCount) buffer PathCount { uint path_count; };

// Phase 0, once its task's sources are walked and its cells pushed: the walk's rays are those
// cells', each kept with the random state its path goes on from (as the core's NextCell gives
// them to the CPU) in the next free slot, not traced. (The walk takes them, so that the
// hemisphere's steps are compiled once: Run.)
bool keeping_cells;
uint keeping_task;
bool KeepCell(int at) {
    if (!keeping_cells) return false;
    uint slot = atomicAdd(path_count, 1u);
    if (slot >= uint(tasks.path_capacity)) {  // (never: the host's capacity is a bound)
        ++dropped;
        reports |= kReportStackFull;
        return true;
    }
    path_starts[slot].r = STACK(at).r;
    path_starts[slot].state = rng;
    path_starts[slot].last = at == 0 ? 1 : 0;  // the hemisphere's item has left the stack
    path_starts[slot].task = keeping_task;
    return true;
}
#endif
// (defined below; -asub's probes in hemisphere.inl ask it first)
bool Intersect(Ray r, out Hit h);
#include "raytrace/core/hemisphere.inl"
#include "raytrace/core/klems.inl"
#include "raytrace/core/bsdf.inl"
#include "raytrace/core/direct.inl"
#include "raytrace/core/materials.inl"

// ---- the nearest hit
vec3 Vertex(uint i) { return vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); }

float ShapeDistance(int s, vec3 org, vec3 dir, float tmin, float tmax) {
    PackedShape g = shapes[s];
    return IntersectShape(g.kind, g.p0.xyz, g.p0.w, g.p1.xyz, g.p1.w, org, dir, tmin, tmax);
}

// Rays leaving a surface (from >= 0) meet every other surface from the start and their own
// object not at all where they start (a polygon never: it is planar; a mesh or analytic surface
// not before tasks.tmin), as the CPU backend's filter has it; other rays start tasks.tmin off.
float StartOf(int from) { return from >= 0 ? 1e-3 * tasks.tmin : tasks.tmin; }
bool OwnTriangle(int p, int from, float t) {
    return triangles[p].object == from && (triangles[p].mesh == 0 || t < tasks.tmin);
}
float ShapeStart(int s, int from) { return shapes[s].object == from ? tasks.tmin : StartOf(from); }

#ifdef DAYFLUX_BVH
// Moller-Trumbore, with a hair of slack at the edges so that rays do not slip between
// triangles sharing one (the hit is moved into its triangle afterwards).
// The triangle's corner a and edges e1, e2 from it come in leaf order (kBindingBvhPrims).
float IntersectTriangle(vec3 a, vec3 e1, vec3 e2, vec3 org, vec3 dir, float tmin, float tmax) {
    vec3 pv = cross(dir, e2);
    float det = dot(e1, pv);
    if (det == 0) return -1;
    float inv = 1.0 / det;
    vec3 tv = org - a;
    float u = dot(tv, pv) * inv;
    if (u < -1e-6 || u > 1 + 1e-6) return -1;
    vec3 q = cross(tv, e1);
    float v = dot(dir, q) * inv;
    if (v < -1e-6 || u + v > 1 + 1e-6) return -1;
    float t = dot(e2, q) * inv;
    return t > tmin && t < tmax ? t : -1;
}

// Where a ray (its inverse direction inv) enters a box within [tmin, t], or kNoEntry where it
// misses it (a hair of slack, for boxes as thin as the polygons they hold).
const float kNoEntry = 3e38;
float BoxEntry(vec3 lo, vec3 hi, vec3 org, vec3 inv, float tmin, float t) {
    vec3 t0 = (lo - org) * inv, t1 = (hi - org) * inv;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, tmin));
    float leave = min(min(tf.x, tf.y), min(tf.z, t));
    return enter <= leave * 1.000001 ? enter : kNoEntry;
}

// The nearest hit: a triangle (shape < 0) or an analytic surface, by walking our BVH (no ray
// queries on this device). Each node tests both its children's boxes; the nearer is walked
// first and the farther kept with its entry, skipped once a hit nearer than that is found
// (the same boxes as testing it then: its entry is all that could fail). Leaf entries are
// triangles, or -(shape + 1).
bool Closest(vec3 org, vec3 dir, int from, out float t, out int prim, out int shape) {
    t = 1e30;
    prim = -1;
    shape = -1;
    if (bvh_nodes.length() == 0) return false;
    float tmin = StartOf(from);
    vec3 safe = mix(vec3(1e-20), -vec3(1e-20), lessThan(dir, vec3(0)));
    vec3 inv = 1.0 / mix(dir, safe, lessThan(abs(dir), vec3(1e-20)));
    int todo[64];
    float todo_entry[64];
    int sp = 0, ref = 0;  // ref: a node's index, or a leaf's ~(first << bits | count)
    while (true) {
        if (ref >= 0) {
            PackedBvhNode n = bvh_nodes[ref];
            float e0 = BoxEntry(n.child[0].lo, n.child[0].hi, org, inv, tmin, t);
            float e1 = BoxEntry(n.child[1].lo, n.child[1].hi, org, inv, tmin, t);
            int r0 = n.child[0].ref, r1 = n.child[1].ref;
            if (e1 < e0) {
                float e = e0; e0 = e1; e1 = e;
                int r = r0; r0 = r1; r1 = r;
            }
            if (e0 < kNoEntry) {
                if (e1 < kNoEntry && sp < 64) {
                    todo[sp] = r1;
                    todo_entry[sp++] = e1;
                }
                ref = r0;
                continue;
            }
        } else {
            int first = ~ref >> kBvhLeafCountBits, count = ~ref & ((1 << kBvhLeafCountBits) - 1);
            for (int i = first; i < first + count; ++i) {
                PackedBvhEntry e = bvh_prims[i];
                int p = e.index;
                if (p >= 0) {
                    float th = IntersectTriangle(e.corner, e.edge1, e.edge2, org, dir, tmin, t);
                    if (th > 0 && !OwnTriangle(p, from, th)) { t = th; prim = p; shape = -1; }
                } else {
                    float th = ShapeDistance(-p - 1, org, dir, ShapeStart(-p - 1, from), t);
                    if (th >= 0 && th < t) { t = th; prim = -p - 1; shape = prim; }
                }
            }
        }
        do {
            if (sp == 0) return prim >= 0;
        } while (todo_entry[--sp] > t * 1.000001);
        ref = todo[sp];
    }
    return false;
}
#else
// The nearest hit: a triangle (shape < 0) or an analytic surface.
// Triangles are opaque (no candidates to filter), so a ray that meets its own object where it
// starts is cast again from beyond that point, from further off each time (at last tasks.tmin).
bool Closest(vec3 org, vec3 dir, int from, out float t, out int prim, out int shape) {
    float tmin = StartOf(from);
    for (int attempt = 0; attempt < 4; ++attempt) {
        rayQueryEXT q;
        rayQueryInitializeEXT(q, scene, gl_RayFlagsOpaqueEXT, 0xFF, org, tmin, dir, 1e30);
        while (rayQueryProceedEXT(q)) {
            if (rayQueryGetIntersectionTypeEXT(q, false) !=
                gl_RayQueryCandidateIntersectionAABBEXT)
                continue;
            float tmax = rayQueryGetIntersectionTypeEXT(q, true) !=
                                 gl_RayQueryCommittedIntersectionNoneEXT
                             ? rayQueryGetIntersectionTEXT(q, true)
                             : 1e30;
            int s = rayQueryGetIntersectionPrimitiveIndexEXT(q, false);
            float th = ShapeDistance(s, org, dir, max(tmin, ShapeStart(s, from)), tmax);
            if (th >= 0) rayQueryGenerateIntersectionEXT(q, th);
        }
        uint type = rayQueryGetIntersectionTypeEXT(q, true);
        if (type == gl_RayQueryCommittedIntersectionNoneEXT) return false;
        t = rayQueryGetIntersectionTEXT(q, true);
        prim = rayQueryGetIntersectionPrimitiveIndexEXT(q, true);
        shape = type == gl_RayQueryCommittedIntersectionGeneratedEXT ? prim : -1;
        if (shape >= 0 || attempt == 3 || !OwnTriangle(prim, from, t)) return true;
        tmin = attempt == 2 ? max(2. * t, tasks.tmin) : max(2. * t, 10. * tmin);
    }
    return false;
}
#endif

uint rays_traced;  // this invocation's nearest-hit queries

// The nearest surface a ray meets (Intersect for the core): a triangle, its hit refined as the
// CPU backend refines it, or an analytic surface. Counted, and with DAYFLUX_RAY_LOG logged for
// a replay (bench/gpu_replay_bench.cpp).
bool Intersect(Ray r, out Hit h) {
    ++rays_traced;
#if defined(DAYFLUX_RAY_LOG) && !defined(DAYFLUX_REPLAY)
    // (the count stops at the capacity: it is read only up to there)
    if (stats_logged < uint(tasks.log_capacity)) {
        uint at = atomicAdd(stats_logged, 1u);
        if (at < uint(tasks.log_capacity)) {
            ray_log[2u * at] = uvec4(floatBitsToUint(r.org), uint(r.from));
            ray_log[2u * at + 1u] = uvec4(floatBitsToUint(r.dir), 0u);
        }
    }
#endif
    float t;
    int prim, shape;
    if (!Closest(r.org, r.dir, r.from, t, prim, shape)) return false;
    if (shape >= 0) {
        PackedShape s = shapes[shape];
        h.point = r.org + t * r.dir;
        h.normal = ShapeNormal(s.kind, s.inward != 0, s.p0.xyz, s.p0.w, s.p1.xyz, s.p1.w, h.point);
        h.surface = s.surface;
        h.object = s.object;
        h.planar = s.kind == kShapeRing;
        h.t = t;
        return true;
    }
    PackedTriangle tri = triangles[prim];
    vec3 a = Vertex(indices[3 * prim]), b = Vertex(indices[3 * prim + 1]),
         c = Vertex(indices[3 * prim + 2]);
    h.point = PointOnTriangle(r.org, r.dir, a, b, c, tri.normal.xyz, t);
    h.surface = tri.surface;
    h.object = tri.object;
    h.planar = tri.planar != 0;
    h.normal = tri.normal.xyz;
    h.t = t;
    return true;
}

#include "raytrace/core/walk.inl"

#ifdef DAYFLUX_REPLAY
// The logged rays [task_offset, task_offset + count) again, nearest hits alone (GPU efficiency's
// denominator, as bench/ray_replay_bench.cpp's replay is the CPU's): a hit's distance (plus
// |normal.x|, so that nothing is optimised away), or -1, into accum.
void main() {
    uint i = gl_GlobalInvocationID.x +
             gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    if (i >= uint(tasks.count)) return;
    uint at = uint(tasks.task_offset) + i;
    Ray r;
    r.org = uintBitsToFloat(ray_log[2u * at].xyz);
    r.from = int(ray_log[2u * at].w);
    r.dir = uintBitsToFloat(ray_log[2u * at + 1u].xyz);
    Hit h;
    accum[i] = ACCUM_T(Intersect(r, h) ? h.t + abs(h.normal.x) : -1.0);
}
#else
// Invocation `slot`'s stack and rows, in scratch.
void UseScratch(uint slot) {
#ifdef DAYFLUX_SCRATCH
    stack_base = slot * uint(STACK_SIZE + 1);
    rows_base = slot * uint(2 * MAXN + DEEP_LEVELS * 2 * DEEP_N);
#endif
}

// Task `local_task`'s input ray: false for a zero direction (counted, contributes nothing).
bool InputRay(uint local_task, out vec3 org, out vec3 dir, out uint index, out uint slice) {
    uint task = uint(tasks.task_offset) + local_task;
    uint ray_in = task / uint(tasks.slices);
    slice = task % uint(tasks.slices);
    // dir.w: the ray's key less first_ray, or -1 for a zero direction
    float key_offset = rays[2 * ray_in + 1].w;
    org = rays[2 * ray_in].xyz;
    dir = normalize(rays[2 * ray_in + 1].xyz);
    index = uint(tasks.first_ray) + uint(max(key_offset, 0.));
    return key_offset >= 0;
}

#ifdef DAYFLUX_PATHS
// 0: the tasks' cells; 1: the walkers' paths, to the last; 2 + 2k and 3 + 2k: wave k of them,
// each walker taking its path to its next ray (2 + 2k), then those rays' nearest hits found
// (3 + 2k), the walkers' state kept between the dispatches (Walker). Any number of waves before
// phase 1 gives the same sums.
layout(push_constant) uniform Phase { uint phase; };
bool WaveRays() { return phase >= 2u && (phase & 1u) == 0u; }
bool WaveHits() { return phase >= 3u && (phase & 1u) == 1u; }
uint Wave() { return (phase - 2u) / 2u; }
layout(std430, set = 0, binding = kBindingWaveQueue) buffer WaveQueue { uint wave_queue[]; };
// Where wave k's queue of walkers lies: after the counts, two queues of a dispatch's walkers each,
// in turn (wave k + 1's next rays read wave k's queue while they fill their own).
uint QueueOf(uint k) {
    return uint(tasks.waves) + (k & 1u) * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
}

// The record a task adds to: its ray's (or its slice's, with tasks_per_record 1).
uint RecordOf(uint local_task) {
    return local_task / uint(tasks.tasks_per_record) * uint(tasks.ncols * 3);
}

// Phase 1's path g, started on the stack (false once g is past the last).
bool StartPath(uint g) {
    if (g >= min(path_count, uint(tasks.path_capacity))) return false;
    acc_base = RecordOf(path_starts[g].task);
    StartCellPath(path_starts[g].r, path_starts[g].state, path_starts[g].last != 0);
    return true;
}

// A walker between dispatches: its path's place (the stack and rows stay in its scratch), the
// ray it stopped at and, once found, that ray's hit (Intersect's fields).
CONST int kWalkerNew = 0;      // (zeroed) its first path not started
CONST int kWalkerTracing = 1;  // its ray `at` waits for its hit
CONST int kWalkerFound = 2;    // and has it
CONST int kWalkerDone = 3;
struct Walker {
    vec3 point;
    int status;
    vec3 normal;
    float t;
    int top, at, surface, object;
    uint rng, g, acc_base;
    int met_planar;  // bit 0: met; bit 1: planar
};
layout(std430, set = 0, binding = kBindingWalkers) buffer Walkers { Walker walkers_state[]; };

// Walker w's state taken up (false where it has no path left): its path g and, where it
// stopped at a ray, `at` and whether its hit was found (met, h).
bool Resume(uint w, inout uint g, out int at, out bool found, out bool met, out Hit h) {
    Walker s = walkers_state[w];
    at = -1;
    found = false;
    met = false;
    if (s.status == kWalkerNew) return StartPath(g);
    if (s.status == kWalkerDone) return false;
    // (a walker stopped at a ray has it traced by the wave's hits, before any later dispatch)
    if (s.status == kWalkerTracing && !WaveHits()) reports |= kReportWaveMissed;
    top = s.top;
    rng = s.rng;
    g = s.g;
    acc_base = s.acc_base;
    at = s.at;
    found = s.status == kWalkerFound;
    met = (s.met_planar & 1) != 0;
    h.point = s.point;
    h.normal = s.normal;
    h.t = s.t;
    h.surface = s.surface;
    h.object = s.object;
    h.planar = (s.met_planar & 2) != 0;
    return true;
}

// Walker w stops at ray `at`, its hit found or not, each step storing only what it changed: the
// rays' dispatch the walker's place (and it joins the wave's queue, so that the hits' dispatch
// takes the walkers with rays in its first invocations), the hits' dispatch the hit.
void Suspend(uint w, uint g, int at, bool found, bool met, Hit h) {
    if (found) {
        walkers_state[w].status = kWalkerFound;
        walkers_state[w].point = h.point;
        walkers_state[w].normal = h.normal;
        walkers_state[w].t = h.t;
        walkers_state[w].surface = h.surface;
        walkers_state[w].object = h.object;
        walkers_state[w].met_planar = (met ? 1 : 0) | (h.planar ? 2 : 0);
        return;
    }
    walkers_state[w].status = kWalkerTracing;
    walkers_state[w].top = top;
    walkers_state[w].at = at;
    walkers_state[w].rng = rng;
    walkers_state[w].g = g;
    walkers_state[w].acc_base = acc_base;
    wave_queue[QueueOf(Wave()) + atomicAdd(wave_queue[Wave()], 1u)] = w;
}
#else
uint RecordOf(uint local_task) { return local_task * uint(tasks.ncols * 3); }
#endif

// Invocation `invocation`'s work: a task's input ray, its sources and then its first
// hemisphere's cells, traced (the paths engine's phase 0: the cells kept, KeepCell); or, in the
// paths engine's other phases, the cells' paths, taken in turn by the dispatch's invocations (the
// host lays its groups all along x, so that their number is the stride). The stack is walked
// (the core's NextRay, the driver's Intersect, the core's ShadeMet, as the CPU's RunStack) in one
// place, so that GPU compilers, which inline every call, compile the shading code once.
void Run(uint invocation) {
    UseScratch(invocation);
    vec3 org, dir;
    uint index, slice;
    int at = -1;         // a ray resumed (the paths engine's waves)
    bool found = false;  // and its hit (met, h)
    bool met = false;
    Hit h;
#ifdef DAYFLUX_PATHS
    uint g = invocation, walkers = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    bool walking = phase != 0u;
    keeping_cells = false;
    keeping_task = invocation;
    if (walking && !Resume(invocation, g, at, found, met, h)) return;
#else
    const bool walking = false;
#endif
    if (!walking) {
        if (invocation >= uint(tasks.count) || !InputRay(invocation, org, dir, index, slice))
            return;
        acc_base = RecordOf(invocation);
        StartInput(org, dir, index, uint(tasks.replica), slice, uint(tasks.slices));
    }
    bool cells_pushed = false;
    DONT_UNROLL while (true) {
        int next;  // (an out argument is undefined where NextRay leaves it unwritten)
        if (at < 0 && NextRay(next)) {
            at = next;
#ifdef DAYFLUX_PATHS
            if (KeepCell(at)) {
                at = -1;
                continue;
            }
            if (WaveRays()) {  // the wave's hits are the next dispatch's
                Suspend(invocation, g, at, false, false, h);
                return;
            }
#endif
        }
        if (at >= 0) {
            if (!found) met = Intersect(STACK(at).r, h);
#ifdef DAYFLUX_PATHS
            if (WaveHits()) {
                Suspend(invocation, g, at, true, met, h);
                return;
            }
#endif
            Ray r = STACK(at).r;
            ShadeMet(r, met, h);
            at = -1;
            found = false;
            continue;
        }
#ifdef DAYFLUX_PATHS
        if (walking) {
            g += walkers;
            if (StartPath(g)) continue;
            walkers_state[invocation].status = kWalkerDone;
            return;
        }
        keeping_cells = true;  // (the sources are walked: what the walk gives next is cells)
#endif
        Item cells;
        if (cells_pushed || !InputCells(org, dir, slice, uint(tasks.slices), cells)) return;
        PushItem(cells);
        cells_pushed = true;
    }
}

void main() {
    top = 0;
    dropped = 0u;
    reports = 0u;
    rays_traced = 0u;
    contribution_pending = false;
#ifdef DAYFLUX_PATHS
    fixed_range_lost = false;
    fixed_sum_lost = false;
#endif
    uint invocation = gl_GlobalInvocationID.x;
#ifdef DAYFLUX_PATHS
    // A wave's hits are its queue's walkers', packed, and so are the next wave's rays (its
    // queue's walkers, now with their hits: the others are done); wave 0's rays are every
    // walker's.
    if (WaveHits() || (WaveRays() && Wave() > 0u)) {
        uint k = WaveHits() ? Wave() : Wave() - 1u;
        if (invocation >= wave_queue[k]) return;
        invocation = wave_queue[QueueOf(k) + invocation];
    }
#endif
    Run(invocation);
#ifdef DAYFLUX_PATHS
    if (fixed_range_lost) reports |= kReportFixedRange;
    if (fixed_sum_lost) reports |= kReportFixedSum;
#endif
    // Items that did not fit the stack are lost: the host says how many.
    if (dropped > 0u) atomicAdd(stats_dropped, dropped);
    if (reports != 0u) atomicOr(stats_reports, reports);
    if (rays_traced > 0u) {  // 64 bits: a dispatch of millions of sensors passes 2^32
        uint before = atomicAdd(stats_rays, rays_traced);
        if (before + rays_traced < before) atomicAdd(stats_rays_high, 1u);
    }
}
#endif
