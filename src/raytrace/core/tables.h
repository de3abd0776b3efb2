// The scene as the estimator core reads it: packed tables of surfaces, sources, analytic shapes,
// triangles and BSDF data, built once on the host (raytrace/packing.h) and read by both drivers:
// from memory on the CPU, from storage buffers on the GPU. Every struct is made of vec4s, vec3s
// each followed by a 4-byte scalar, and 4-byte scalars in multiples of four, so the std430 layout
// and the C++ layout agree without padding rules (static_asserts in packing.cpp).
#ifndef DAYFLUX_CORE_TABLES_H
#define DAYFLUX_CORE_TABLES_H

#include "raytrace/core/language.h"
#include "raytrace/core/sampling.h"  // kTiny

#ifdef __cplusplus
namespace dayflux::core {
#endif

// Analytic surfaces, as scene/flatten.h's AnalyticShape::Kind.
CONST int kShapeSphere = 0;
CONST int kShapeCone = 1;
CONST int kShapeCylinder = 2;
CONST int kShapeRing = 3;

// Material kinds, as raytrace/materials.h's Material::Kind.
CONST int kMatBlack = 0;
CONST int kMatDiffuse = 1;
CONST int kMatGlass = 2;
CONST int kMatMirror = 3;
CONST int kMatGlow = 4;
CONST int kMatLight = 5;
CONST int kMatMix = 6;         // mixfunc: `pattern` mixes surfaces `fore` and `back` (-1: void)
CONST int kMatBsdf = 7;        // BSDF (Klems): its data at klems[fore]
CONST int kMatDielectric = 8;  // color: transmission per unit length, w: the index
// kMatLight, kMatIllum: params.xyz a spotlight's axis, params.w its focus distance, alpha2 the
// cone's solid angle (0: not a spot); kMatIllum: fore is its alternate material (-1: void).
CONST int kMatIllum = 9;
// antimatter (m_clip()): fore holds the bits of the modifiers it clips, back the surface of the
// material for its inside (-1: void), pattern the bits of its penetration counters.
CONST int kMatAntimatter = 10;

// An inner node of the BVH the GPU walks where it has no ray queries (raytrace/bvh.h's
// PackBvh): its two children's bounds, so that one load tests both and the nearer is walked
// first. A child's reference is an inner node's index, or a leaf's ~(first << kBvhLeafCountBits
// | count), its entries bvh_prims[first .. first + count - 1]. Node 0 is the root.
struct PackedBvhChild {
    vec3 lo;
    int ref;
    vec3 hi;
    int pad;
};
struct PackedBvhNode {
    PackedBvhChild child[2];
};
CONST int kBvhLeafCountBits = 3;  // a leaf holds at most 7 primitives
// A leaf's entry: a triangle's corner and its two edges from it (what the walk's test takes), or
// an analytic shape; index: the triangle, or -(shape + 1).
struct PackedBvhEntry {
    vec3 corner;
    int index;
    vec3 edge1;
    int pad0;
    vec3 edge2;
    int pad1;
};

struct PackedTriangle {
    vec4 normal;  // unit geometric normal (triangle winding); w unused
    int surface;  // index into the surfaces
    int object;   // scene object (sources' objects are compared with it)
    int mesh;     // 1: a mesh's (not planar as a polygon is: it may meet rays leaving it)
    int planar;   // 1: flat to m_normal() (SP_FLAT: a polygon's, or a void mesh's with a
                  // material of its own, which RADIANCE shades as a face)
};

// A material as the integrator needs it, with the tracked modifier it counts for.
// PackedSurface.params.w: a metal; trans or glass (-i passes through it).
CONST int kSurfaceMetal = 1;
CONST int kSurfaceTransparent = 2;
// A mirror naming a substitute material (m_mirror()'s string argument): fore is it (-1: void).
CONST int kSurfaceMirrorAlternate = 4;
// A receiver -asub samples directly (the receivers table below): a glow counting for a modifier,
// on triangles only, clipped by no antimatter.
CONST int kSurfaceSampled = 8;
// An aBSDF (kMatBsdf): a peak of its transmission about the straight-through direction passes
// rays unscattered.
CONST int kSurfaceAperture = 16;

struct PackedSurface {
    vec4 color;    // rgb; w: glass refractive index
    vec4 params;   // x: specularity, y: transmissivity, z: transmitted specular fraction, w: flags
    int kind;      // kMat*
    int tracked;   // -m index, or -1
    float alpha2;  // roughness squared (0: pure specular)
    int pattern;   // brightfunc/colorfunc multiplying the colour, or -1 (mixfunc: its mix)
    int fore, back;  // mixfunc: its two materials' surfaces (-1: void)
    uint clip;       // the antimatter bit of the surface's modifier: a ray whose clip set has
                     // it passes unseen (RADIANCE's raycont())
    int counter;     // the penetration counter of that bit (antimatter with an inside), or -1
};

// An antimatter surface's fields by name (packing.cpp writes them there): the clip bits of the
// modifiers it cuts (fore), the surface of the material for its inside (back; -1: void), and the
// penetration counters that tell whether a ray went into what it cuts (pattern's bits).
inline uint AntimatterClips(PackedSurface m) { return uint(m.fore); }
inline int AntimatterInside(PackedSurface m) { return m.back; }
inline uint AntimatterCounters(PackedSurface m) { return uint(m.pattern); }

// Whether a shadow ray meeting the surface, from either side, ends there and brings nothing
// (Shade pushes no ray for it): black, or plastic, metal and trans without pure specular
// transmission (rough transmission is sampled only for rays other than shadow rays), clipped
// by no antimatter and counting for no modifier. Such surfaces form the blockers that
// a driver may test shadow rays against at once (direct.inl's ShadowRay).
inline bool StopsShadowRays(PackedSurface m) {
    if (m.clip != 0u || m.tracked >= 0) return false;
    // (tspec = params.y (1 - rspec) params.z is nought only where one of them is: out-of-range
    // values of either may still transmit)
    return m.kind == kMatBlack ||
           (m.kind == kMatDiffuse && (m.params.y == 0. || m.params.z == 0. || m.alpha2 > kTiny));
}

// An analytic surface (sphere/bubble, cone/cup, cylinder/tube, ring), recentred.
struct PackedShape {
    vec4 p0;      // xyz: centre (sphere, ring) or first end (cone, cylinder); w: r0
    vec4 p1;      // xyz: second end (cone, cylinder) or the ring's normal; w: r1
    int kind;     // kShape*
    int inward;   // bubble, cup, tube: normals point inside
    int surface;  // index into the surfaces
    int object;   // scene object
};

// Light sources, as raytrace/materials.h's Source: distant (RADIANCE's 'source') or local, a
// polygon or ring (flat), sphere or cylinder with light or illum. Flags in PackedSource.v.w.
CONST int kSourceDistant = 0;
CONST int kSourceFlat = 1;
CONST int kSourceSphere = 2;
CONST int kSourceCylinder = 3;
CONST int kSourceCircular = 1;  // round: samples are trimmed toward a disc
CONST int kSourceTurned = 2;    // sampled over a square turned at random
CONST int kSourceWeak = 4;      // illum (or glow): passes rays aimed at others

struct PackedSource {
    vec4 dir;     // distant: unit direction, w: solid angle; local: centre (recentred), w: area
    vec4 colour;  // rgb radiance of its material; w: 1 for glow (found only by escaping rays)
    vec4 u;       // distant: half side of the square -dj jitters over; local: ss[SU]; w: shape
    vec4 v;       // distant: the other half side; local: ss[SV]; w: flags
    vec4 w;       // local: ss[SW]; w: a cylinder's radius. Distant: the cosine and sine of the
                  // angle -dj turns a sample by at most (an image's cone, InMirrorsCone())
    vec4 norm;    // a flat source's normal or a cylinder's axis; w: spot cone (0: not a spot)
    vec4 spot;    // a spotlight's axis; w: its focus distance
    int object;   // scene object (an image's: its mirror)
    int tracked;  // -m index, or -1
    int kind;     // its material's kMat*
    int pattern;  // brightfunc/colorfunc of its material (the sky's skyfunc), or -1
    // An image of source `next` in mirror `relay` (RADIANCE's virtual sources, -dr), else -1.
    // The mirror's plane and outline are in the relays table: relay r's vec4s at 3r are
    // (normal, offset), (centre, radius squared), (first vertex, vertices, inner radius squared
    // of a ring, 0); its vertices (recentred xyz) follow all relays' headers.
    int relay;
    int next;
    int pad0, pad1;
};

// Whether shadow rays toward source s may ask the blockers (StopsShadowRays) instead of walking:
// a distant source (a sun), not an image in a mirror, not a glow (which sends no shadow rays).
inline bool ShadowRaysAskBlockers(PackedSource s) {
    return int(s.u.w) == kSourceDistant && s.relay < 0 && s.colour.w < 0.5;
}

// The receivers -asub samples from diffuse surfaces below the first hemisphere (hemisphere.inl's
// SampleReceivers): the triangles of the surfaces flagged kSurfaceSampled, recentred, as vec4s.
// A header (x: their total area, y: how many), then three per triangle: (first vertex, the
// triangles' cumulative area up to and including this one), (first edge, its object), (second
// edge, 0).

// A tracked modifier (ivec4 per -m): its first column in a record, its number of bins, and its
// bin function.
CONST int kTrackedColumn = 0;
CONST int kTrackedBins = 1;
CONST int kTrackedFunction = 2;

// The BSDF material's Klems data in the klems table (raytrace/packing.cpp's PackKlems), floats
// from offset b: the header, then its parts. Offsets are stored as floats (exact below 2^24).
CONST int kKlemsThickness = 0;        // the thickness (0: none)
CONST int kKlemsUp = 1;               // 3: the up vector
CONST int kKlemsLambertian = 4;       // 4: the Lambertian totals, rf rb tf tb
CONST int kKlemsFrontReflection = 8;  // 3: the material's own diffuse colours
CONST int kKlemsBackReflection = 11;  // 3
CONST int kKlemsTransmission = 14;    // 3
CONST int kKlemsParts = 17;           // 4: offsets of the parts rf rb tf tb (-1: none)
// Patterns giving the thickness and the up vector where they depend on the ray (-1: constant).
CONST int kKlemsThicknessPattern = 21;
CONST int kKlemsUpPattern = 22;
CONST int kKlemsHeader = 23;
// A part (one matrix) at offset q: the side each basis lies on, its largest hemispherical
// total, its sizes, its two bases' tables, its values (nout x nin) and the cumulative
// distributions per incident patch (forward) and per outgoing patch (reverse), each a row of
// n + 1 sums.
CONST int kPartInFront = 0;
CONST int kPartOutFront = 1;
CONST int kPartMaxHemi = 2;
CONST int kPartInSize = 3;
CONST int kPartOutSize = 4;
CONST int kPartInRings = 5;
CONST int kPartOutRings = 6;
CONST int kPartInBasis = 7;    // 4 offsets: a basis table (kBasis*)
CONST int kPartOutBasis = 11;  // 4
CONST int kPartValues = 15;
CONST int kPartCdf = 16;
CONST int kPartReverseCdf = 17;
CONST int kPartMinProjSA = 18;  // the smallest projected solid angle of its patches
CONST int kPartHeader = 19;
// A basis table's offsets, from a part's kPartInBasis or kPartOutBasis: its rings' bounding
// cosines (rings + 1), azimuth counts, first patches and the patches' projected solid angles.
CONST int kBasisCosines = 0;
CONST int kBasisAzimuths = 1;
CONST int kBasisFirst = 2;
CONST int kBasisSolidAngles = 3;

// What the core reports to its driver (`reports`), which warns about each once.
CONST uint kReportBadBin = 1u;     // a bin beyond -bn (RADIANCE: "bad bin number")
CONST uint kReportBsdfFrame = 2u;  // a BSDF's up vector along its normal
CONST uint kReportStackFull = 4u;  // items that did not fit the ray stack (`dropped`)
// A contribution the GPU's paths engine could not hold in its fixed point (beyond 8192 times its
// scale, or NaN), left out; set by that driver alone.
CONST uint kReportFixedRange = 8u;
// A record's sum in that fixed point passed its range (2^63 units: 32768 times its scale), so that
// its values are wrong; set by that driver alone.
CONST uint kReportFixedSum = 16u;
// A wave's walker that stopped at a ray found it untraced at the next wave (an invariant of that
// driver's queue, which its host checks).
CONST uint kReportWaveMissed = 32u;

#ifdef __cplusplus
}  // namespace dayflux::core
#endif
#endif  // DAYFLUX_CORE_TABLES_H
