// Bindings and struct layouts shared by the C++ host (src/raytrace/vulkan) and the GLSL
// integrator (contrib.comp). Every struct is made of vec4s and ints in multiples of four, so the
// std430 layout and the C++ layout agree without padding rules.
#ifdef __cplusplus
#pragma once
#include <cstdint>
namespace dayflux::gpu {
using uint = uint32_t;
struct alignas(16) vec4 {
    float x = 0, y = 0, z = 0, w = 0;
};
#define DAYFLUX_GPU_CONST inline constexpr int
#else
#define DAYFLUX_GPU_CONST const int
#endif

// Set 0 bindings. Binding 0 is the scene: the acceleration structure with ray queries, else our
// own BVH's nodes (GpuBvhNode), with its primitive list at kBindingBvhPrims (GpuDevice::Run).
DAYFLUX_GPU_CONST kBindingRays = 1;       // vec4 org (xyz, recentred), vec4 dir per input ray
DAYFLUX_GPU_CONST kBindingPositions = 2;  // float xyz per vertex, recentred
DAYFLUX_GPU_CONST kBindingIndices = 3;    // uint, 3 per triangle
DAYFLUX_GPU_CONST kBindingTriangles = 4;  // GpuTriangle per triangle
DAYFLUX_GPU_CONST kBindingSurfaces = 5;   // GpuSurface per surface kind
DAYFLUX_GPU_CONST kBindingSources = 6;    // GpuSource per distant source
DAYFLUX_GPU_CONST kBindingAccum = 7;      // double, tasks x columns x 3
DAYFLUX_GPU_CONST kBindingTasks = 8;      // GpuTasks: what this dispatch does
DAYFLUX_GPU_CONST kBindingStats = 9;      // uint: stack items dropped (should stay 0)
DAYFLUX_GPU_CONST kBindingShapes = 10;    // GpuShape per analytic surface (procedural boxes)
DAYFLUX_GPU_CONST kBindingBvhPrims = 11;  // int per BVH leaf entry: triangle, or shape + triangles
DAYFLUX_GPU_CONST kBindingKlems = 12;     // float: the BSDF materials' Klems data (PackKlems)
DAYFLUX_GPU_CONST kBindingRelays = 13;    // vec4: the mirrors that relay sources (GpuSource.relay)
DAYFLUX_GPU_CONST kBindingTracked = 14;   // ivec4 per tracked modifier: first column, bins, bin
                                          // function (EvalBin), 0

// Analytic surfaces, as scene/flatten.h's AnalyticShape::Kind.
DAYFLUX_GPU_CONST kShapeSphere = 0;
DAYFLUX_GPU_CONST kShapeCone = 1;
DAYFLUX_GPU_CONST kShapeCylinder = 2;
DAYFLUX_GPU_CONST kShapeRing = 3;

// Material kinds, as raytrace/materials.h's Material::Kind.
DAYFLUX_GPU_CONST kMatBlack = 0;
DAYFLUX_GPU_CONST kMatDiffuse = 1;
DAYFLUX_GPU_CONST kMatGlass = 2;
DAYFLUX_GPU_CONST kMatMirror = 3;
DAYFLUX_GPU_CONST kMatGlow = 4;
DAYFLUX_GPU_CONST kMatLight = 5;
DAYFLUX_GPU_CONST kMatMix = 6;   // mixfunc: `pattern` mixes surfaces `fore` and `back` (-1: void)
// The sides of mixfuncs a hit may have waiting to be shaded: a tree of mixfuncs nested n deep
// needs n + 1.
DAYFLUX_GPU_CONST kMixStack = 8;
DAYFLUX_GPU_CONST kMatBsdf = 7;  // BSDF (Klems): its data at klems[fore]
DAYFLUX_GPU_CONST kMatDielectric = 8;  // color: transmission per unit length, w: the index
// kMatLight, kMatIllum: params.xyz a spotlight's axis, params.w its focus distance, alpha2 the
// cone's solid angle (0: not a spot); kMatIllum: fore is its alternate material (-1: void).
DAYFLUX_GPU_CONST kMatIllum = 9;
// antimatter (m_clip() with a void inside): fore holds the bits of the modifiers it clips.
DAYFLUX_GPU_CONST kMatAntimatter = 10;

// A node of the BVH traversed where there are no ray queries (raytrace/bvh.h), depth first: an
// inner node's first child follows it, `index` is its second; a leaf's primitives are
// bvh_prims[index .. index + count - 1].
struct GpuBvhNode {
    vec4 lo, hi;  // bounds (xyz)
    int count;    // 0: inner node
    int index;
    int pad0, pad1;
};

struct GpuTriangle {
    vec4 normal;  // unit geometric normal (triangle winding); w unused
    int surface;  // index into the surfaces
    int object;   // scene object (sources' objects are compared with it)
    int mesh;     // 1: a mesh's (not planar as a polygon is: it may meet rays leaving it)
    int pad1;
};

// A material as the integrator needs it, with the tracked modifier it counts for.
// GpuSurface.params.w: a metal; trans or glass (-i passes through it).
DAYFLUX_GPU_CONST kSurfaceMetal = 1;
DAYFLUX_GPU_CONST kSurfaceTransparent = 2;
// A mirror naming a substitute material (m_mirror()'s string argument): fore is it (-1: void).
DAYFLUX_GPU_CONST kSurfaceMirrorAlternate = 4;

struct GpuSurface {
    vec4 color;    // rgb; w: glass refractive index
    vec4 params;   // x: specularity, y: transmissivity, z: transmitted specular fraction, w: flags
    int kind;      // kMat*
    int tracked;   // -m index, or -1
    float alpha2;  // roughness squared (0: pure specular)
    int pattern;   // brightfunc/colorfunc multiplying the colour, or -1 (mixfunc: its mix)
    int fore, back;  // mixfunc: its two materials' surfaces (-1: void)
    uint clip;       // the antimatter bit of the surface's modifier: a ray whose clip set has
                     // it passes unseen (RADIANCE's raycont())
    int pad1;
};

// An analytic surface (sphere/bubble, cone/cup, cylinder/tube, ring), recentred.
struct GpuShape {
    vec4 p0;      // xyz: centre (sphere, ring) or first end (cone, cylinder); w: r0
    vec4 p1;      // xyz: second end (cone, cylinder) or the ring's normal; w: r1
    int kind;     // kShape*
    int inward;   // bubble, cup, tube: normals point inside
    int surface;  // index into the surfaces
    int object;   // scene object
};

// Light sources, as raytrace/materials.h's Source: distant (RADIANCE's 'source') or local, a
// polygon or ring (flat), sphere or cylinder with light or illum. Flags in GpuSource.v.w.
DAYFLUX_GPU_CONST kSourceDistant = 0;
DAYFLUX_GPU_CONST kSourceFlat = 1;
DAYFLUX_GPU_CONST kSourceSphere = 2;
DAYFLUX_GPU_CONST kSourceCylinder = 3;
DAYFLUX_GPU_CONST kSourceCircular = 1;  // round: samples are trimmed toward a disc
DAYFLUX_GPU_CONST kSourceTurned = 2;    // sampled over a square turned at random
DAYFLUX_GPU_CONST kSourceWeak = 4;      // illum (or glow): passes rays aimed at others

struct GpuSource {
    vec4 dir;     // distant: unit direction, w: solid angle; local: centre (recentred), w: area
    vec4 colour;  // rgb radiance of its material; w: 1 for glow (found only by escaping rays)
    vec4 u;       // distant: half side of the square -dj jitters over; local: ss[SU]; w: shape
    vec4 v;       // distant: the other half side; local: ss[SV]; w: flags
    vec4 w;       // local: ss[SW]; w: a cylinder's radius
    vec4 norm;    // a flat source's normal or a cylinder's axis; w: spot cone (0: not a spot)
    vec4 spot;    // a spotlight's axis; w: its focus distance
    int object;   // scene object (an image's: its mirror)
    int tracked;  // -m index, or -1
    int kind;     // its material's kMat*
    int pattern;  // brightfunc/colorfunc of its material (the sky's skyfunc), or -1
    // An image of source `next` in mirror `relay` (RADIANCE's virtual sources, -dr), else -1.
    // The mirror's plane and outline are in the relays buffer: relay r's vec4s at 3r are
    // (normal, offset), (centre, radius squared), (first vertex, vertices, inner radius squared
    // of a ring, 0); its vertices (recentred xyz) follow all relays' headers.
    int relay;
    int next;
    int pad0, pad1;
};

// One dispatch: tasks [task_offset, task_offset + count) of rays x slices; a slice traces a
// share of the rows of the first hemisphere (the rest of a path follows the cell that started
// it). Results: count x columns x 3 doubles. The run's options are here too, not compiled in,
// so one compiled shader serves every run with the same bins (compiling is slow on lavapipe).
struct GpuTasks {
    int rays;           // input rays in the batch (the rays buffer)
    int slices;         // tasks per ray
    int first_ray;      // index of the batch's first ray in the whole input (random numbers)
    int replica;        // -se replica (random numbers)
    int task_offset;    // first task of this dispatch
    int count;          // tasks in this dispatch
    int ab, ad;         // -ab, -ad
    int lr;             // -lr
    int irradiance;     // -I
    int first_hit;      // -i
    int contributions;  // -V
    int nsources;
    uint seed;
    int ndirect;  // sources sampled with shadow rays (not glow)
    int ncols;    // columns of a record (all tracked modifiers' bins)
    float lw, dj, tmin, st;                     // -lw, -dj, the ray start offset, -st
    float ss, ds, pad3, pad4;                   // -ss, -ds
    double centre_x, centre_y, centre_z, pad5;  // added back to positions for the bins
};

#ifdef __cplusplus
}  // namespace dayflux::gpu
#endif
