// RADIANCE's analytic surfaces (sphere/bubble, cone/cup, cylinder/tube, ring): where a ray meets
// one and the normal there, as exact surfaces rather than tessellations. The CPU's Embree user
// geometry (raytrace/analytic.cpp) calls these in double, the GPU in float on recentred shapes.
// A shape is its kind (kShape*), p0 (centre, or first end), r0, p1 (second end, or a ring's
// normal) and r1.
#ifndef DAYFLUX_CORE_SHAPES_H
#define DAYFLUX_CORE_SHAPES_H

#include "raytrace/core/language.h"
#include "raytrace/core/tables.h"

#ifdef __cplusplus
namespace dayflux::core {
#endif

// Roots of a t^2 + b t + c = 0 in increasing order; false if none. (1e-30 stands for zero: it
// is representable in float.)
inline bool Quadratic(real a, real b, real c, OUT(real) t0, OUT(real) t1) {
    if (abs(a) < 1e-30) {
        if (abs(b) < 1e-30) return false;
        t0 = t1 = -c / b;
        return true;
    }
    real disc = b * b - 4. * a * c;
    if (disc < 0.) return false;
    real q = -0.5 * (b + (b < 0. ? -sqrt(disc) : sqrt(disc)));
    real x0 = q / a, x1 = q != 0. ? c / q : x0;
    t0 = min(x0, x1);
    t1 = max(x0, x1);
    return true;
}

// The nearest t in (tmin, tmax) where the ray org + t dir (dir of unit length) meets the shape,
// or -1.
inline real IntersectShape(int kind, real3 p0, real r0, real3 p1, real r1, real3 org, real3 dir,
                           real tmin, real tmax) {
    real t0, t1;
    if (kind == kShapeSphere) {
        real3 oc = org - p0;
        if (!Quadratic(1.0, 2. * dot(oc, dir), dot(oc, oc) - r0 * r0, t0, t1)) return -1.;
        if (t0 > tmin && t0 < tmax) return t0;
        if (t1 > tmin && t1 < tmax) return t1;
        return -1.;
    }
    if (kind == kShapeRing) {
        real3 n = normalize(p1);
        real dn = dot(dir, n);
        if (abs(dn) < 1e-30) return -1.;
        real t = dot(p0 - org, n) / dn;
        if (!(t > tmin && t < tmax)) return -1.;
        real3 x = org + t * dir - p0;
        real r2 = dot(x, x);
        return r2 >= r0 * r0 && r2 <= r1 * r1 ? t : -1.;
    }
    // cone, cylinder: |wp + t dp|^2 = (r0 + slope (wu + t du))^2 along the axis
    real3 d = p1 - p0;
    real len = length(d);
    real3 u = d / len;
    real slope = (r1 - r0) / len;
    real3 w = org - p0;
    real wu = dot(w, u), du = dot(dir, u);
    real3 wp = w - wu * u, dp = dir - du * u;
    real rw = r0 + slope * wu, rd = slope * du;
    if (!Quadratic(dot(dp, dp) - rd * rd, 2. * (dot(wp, dp) - rw * rd), dot(wp, wp) - rw * rw, t0,
                   t1))
        return -1.;
    for (int k = 0; k < 2; ++k) {
        real t = k == 0 ? t0 : t1;
        if (!(t > tmin && t < tmax)) continue;
        real z = wu + t * du;
        if (z < 0. || z > len || r0 + slope * z < 0.) continue;
        return t;
    }
    return -1.;
}

// The unit normal at p on the shape: outward for sphere, cone and cylinder (the radial direction
// tilted back by the radius' slope), inward for bubble, cup and tube, a ring's own normal.
inline real3 ShapeNormal(int kind, bool inward, real3 p0, real r0, real3 p1, real r1, real3 p) {
    real3 n;
    if (kind == kShapeSphere) {
        n = p - p0;
    } else if (kind == kShapeRing) {
        n = p1;
    } else {
        real3 d = p1 - p0;
        real len = length(d);
        real3 u = d / len;
        real slope = (r1 - r0) / len;
        real3 w = p - p0;
        real3 radial = w - dot(w, u) * u;
        real rl = length(radial);
        n = (rl > 0. ? radial / rl : real3(0)) - slope * u;
    }
    if (dot(n, n) == 0.) return real3(0);
    n = normalize(n);
    return inward ? -n : n;
}

// The point of triangle abc closest to p (Ericson, Real-Time Collision Detection, 5.1.5).
inline real3 ClosestPointOnTriangle(real3 p, real3 a, real3 b, real3 c) {
    real3 ab = b - a, ac = c - a, ap = p - a;
    real d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0. && d2 <= 0.) return a;
    real3 bp = p - b;
    real d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0. && d4 <= d3) return b;
    real vc = d1 * d4 - d3 * d2;
    if (vc <= 0. && d1 >= 0. && d3 <= 0.) return a + (d1 / (d1 - d3)) * ab;
    real3 cp = p - c;
    real d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0. && d5 <= d6) return c;
    real vb = d5 * d2 - d1 * d6;
    if (vb <= 0. && d2 >= 0. && d6 <= 0.) return a + (d2 / (d2 - d6)) * ac;
    real va = d3 * d6 - d5 * d4;
    if (va <= 0. && (d4 - d3) >= 0. && (d5 - d6) >= 0.)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    real denom = 1. / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// t set to the distance along the ray to the plane through a with normal n (any length), where
// the ray meets it ahead; false (t kept) where it does not.
inline bool OntoPlane(real3 org, real3 dir, real3 a, real3 n, INOUT(real) t) {
    real dn = dot(dir, n);
    if (dn == 0.) return false;
    real tp = dot(a - org, n) / dn;
    if (tp <= 0.) return false;
    t = tp;
    return true;
}

// A hit on triangle abc (normal n, any length) refined: t from the ray's meeting with the
// triangle's plane, the point moved into the triangle where the traversal, in float, reported a
// hit a hair beyond an edge (so that new rays never start outside a closed room).
inline real3 PointOnTriangle(real3 org, real3 dir, real3 a, real3 b, real3 c, real3 n,
                             INOUT(real) t) {
    OntoPlane(org, dir, a, n, t);
    return ClosestPointOnTriangle(org + t * dir, a, b, c);
}

#ifdef __cplusplus
}  // namespace dayflux::core
#endif
#endif  // DAYFLUX_CORE_SHAPES_H
