// Constants, colour measures and sampling maps shared by both drivers (and by the tests that
// predict where samples land).
#ifndef DAYFLUX_CORE_SAMPLING_H
#define DAYFLUX_CORE_SAMPLING_H

#include "raytrace/core/language.h"

#ifdef __cplusplus
namespace dayflux::core {
#endif

CONST real kTiny = 1e-6;  // RADIANCE's FTINY
CONST real kPi = 3.14159265358979323846;
CONST real kFresnelThreshold = 0.017999;

inline real Max3(real3 c) { return max(c.x, max(c.y, c.z)); }
// RADIANCE's bright(): luminance weights of its standard primaries.
inline real Bright(real3 c) { return dot(c, real3(0.2651058, 0.6701058, 0.0647884)); }
// RADIANCE's Fresnel estimate for pure specular plastic and metal (normal.c).
inline real FresnelEstimate(real cosi) { return exp(-5.85 * cosi) - 0.00287989916; }

// RADIANCE's checknorm(): v, of length 1 to rounding already (a sum of orthonormal vectors
// weighted by the coordinates of a unit vector), normalised only where it is not; on the CPU,
// where the square root and division took 6 % of the office's DC run. The GPU's float always
// normalises: float lengths are off by up to 1e-7, which the collision rule at -ad 90000
// (thresholds 3e-6 below 1) turned into 3e-4 between the engines, against 5e-6 normalised.
inline real3 CheckNorm(real3 v) {
#ifdef __cplusplus
    real l2 = dot(v, v);
    return abs(1. - l2) <= kTiny ? v : v / sqrt(l2);
#else
    return normalize(v);
#endif
}

// Two unit vectors perpendicular to n and to each other.
inline void Tangents(real3 n, OUT(real3) u, OUT(real3) v) {
    real3 e = abs(n.x) < 0.6 ? real3(1, 0, 0) : (abs(n.y) < 0.6 ? real3(0, 1, 0) : real3(0, 0, 1));
    u = normalize(cross(e, n));
    v = cross(n, u);
}

// RADIANCE's getperpendicular() with randomize on, as its ambient hemispheres use it: a tangent
// turned by a random amount about n (r0..r3 uniform in [0, 1)). The turn matters because the
// sample-collision rule (ambcollision()) is not invariant to it.
inline real3 RandomTangent(real3 n, real r0, real r1, real r2, real r3) {
    real3 e = real3(0.5 - r0, 0.5 - r1, 0.5 - r2);
    int o = min(5, int(r3 * 6.));
    ivec3 ord = o == 0   ? ivec3(0, 1, 2)
                : o == 1 ? ivec3(0, 2, 1)
                : o == 2 ? ivec3(1, 0, 2)
                : o == 3 ? ivec3(1, 2, 0)
                : o == 4 ? ivec3(2, 0, 1)
                         : ivec3(2, 1, 0);
    int i = 2;
    while (i > 0 && !(abs(n[ord[i]]) < 0.6)) --i;
    e[ord[i]] = 1.0;
    return normalize(cross(e, n));
}

// sin and cos of x in [-pi/4, pi/4]: on the CPU by their Taylor series to x^17 and x^18 (the
// first terms left out are below 1e-19 there), within an ulp or two of libm's double sincos at a
// fraction of its cost (the hemispheres take one a sample); on the GPU by its own sin and cos,
// whose float is more exact than a float series (the collision rule below is sensitive to
// that: a series in float moved -ad 90000 runs 4e-4 away from Embree's, against 5e-6). (The
// literals are floating point: glslang lexes skipped lines and refuses integers beyond 32 bits.)
inline void SinCosQuarter(real x, OUT(real) s, OUT(real) c) {
#ifdef __cplusplus
    real x2 = x * x;
    s = x * (1. + x2 * (-1. / 6. + x2 * (1. / 120. + x2 * (-1. / 5040. + x2 * (1. / 362880. +
        x2 * (-1. / 39916800. + x2 * (1. / 6227020800. + x2 * (-1. / 1307674368000. +
        x2 * (1. / 355687428096000.)))))))));
    c = 1. + x2 * (-1. / 2. + x2 * (1. / 24. + x2 * (-1. / 720. + x2 * (1. / 40320. +
        x2 * (-1. / 3628800. + x2 * (1. / 479001600. + x2 * (-1. / 87178291200. +
        x2 * (1. / 20922789888000. + x2 * (-1. / 6402373705728000.)))))))));
#else
    s = sin(x);
    c = cos(x);
#endif
}

// Shirley-Chiu: unit square to unit disk, area-preserving (RADIANCE's square2disk()). Its four
// cases are two: |a| > |b| turns by pi/4 (b/a) with radius a, else by pi/4 (a/b) with radius
// b (the signs place the quadrant), so only a quarter turn's sine and cosine are needed. The
// case is chosen by selects, not branches: which one a sample falls in is random.
inline real2 SquareToDisk(real sx, real sy) {
    real a = 2. * sx - 1., b = 2. * sy - 1.;
    bool by_a = abs(a) > abs(b);
    real num = by_a ? b : a, den = by_a ? a : b;
    if (den == 0.) return real2(0., 0.);
    real s, c;
    SinCosQuarter(kPi / 4. * (num / den), s, c);
    return real2(den * (by_a ? c : s), den * (by_a ? s : c));
}

#ifdef __cplusplus
}  // namespace dayflux::core
#endif
#endif  // DAYFLUX_CORE_SAMPLING_H
