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
// Frisvad's basis as Duff et al. (2017) made it exact near n.z = -1: one division, no square
// root (the single-cell hemispheres below the first bounce take one a vertex).
inline void Tangents(real3 n, OUT(real3) u, OUT(real3) v) {
    real s = n.z >= 0. ? 1. : -1.;
    real a = -1. / (s + n.z);
    real b = n.x * n.y * a;
    u = real3(1. + s * n.x * n.x * a, s * b, -s * n.x);
    v = real3(b, s + n.y * n.y * a, -n.y);
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

// sin and cos of x in [-pi/4, pi/4]: on the CPU by the minimax polynomials of fdlibm's kernels
// (k_sin.c, k_cos.c: degree 13 and 14, error below 2^-58 on that interval, the coefficients are
// theirs), within an ulp of libm's double sincos at a fraction of its cost (the hemispheres take
// one a sample; the Taylor series to x^17 it replaced had two more steps in each chain); on the
// GPU by its own sin and cos, whose float is more exact than a float polynomial (the collision
// rule below is sensitive to that: a series in float moved -ad 90000 runs 4e-4 away from
// Embree's, against 5e-6). cos is fdlibm's 1 - x^2/2 with the rounding of that difference put
// back. (The literals are floating point: glslang lexes skipped lines too.)
inline void SinCosQuarter(real x, OUT(real) s, OUT(real) c) {
#ifdef __cplusplus
    real z = x * x;
    real rs = 8.33333333332248946124e-03 +
              z * (-1.98412698298579493134e-04 +
                   z * (2.75573137070700676789e-06 +
                        z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
    s = x + z * x * (-1.66666666666666324348e-01 + z * rs);
    real rc =
        z * (4.16666666666666019037e-02 +
             z * (-1.38888888888741095749e-03 +
                  z * (2.48015872894767294178e-05 +
                       z * (-2.75573143513906633035e-07 +
                            z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
    real hz = 0.5 * z, w = 1. - hz;
    c = w + (((1. - w) - hz) + z * rc);
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
