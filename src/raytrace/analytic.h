// Ray intersections with RADIANCE's analytic surfaces (sphere/bubble, cone/cup, cylinder/tube,
// ring) as flattened scenes hold them, in double precision, for the Embree backend: the estimator
// core's (raytrace/core/shapes.h), which the GPU runs in float.
#pragma once

#include "scene/flatten.h"

namespace dayflux {

// The estimator core's kind of shape (core/tables.h's kShape*; a source is none of them).
int CoreShapeKind(AnalyticShape::Kind kind);

// The nearest t in (tmin, tmax) where the ray org + t dir (dir of unit length) meets the shape,
// or a negative number. offset is subtracted from the shape's coordinates first (a backend's
// recentring).
double IntersectShape(const AnalyticShape &shape, const double offset[3], const double org[3],
                      const double dir[3], double tmin, double tmax);

// The unit surface normal at point p on the shape (outward for sphere, cone, cylinder; inward
// for bubble, cup, tube; the ring's own normal), p in the same recentred coordinates.
void ShapeNormal(const AnalyticShape &shape, const double offset[3], const double p[3],
                 double normal[3]);

// An axis-aligned box holding the shape (recentred).
void ShapeBounds(const AnalyticShape &shape, const double offset[3], double lo[3], double hi[3]);

}  // namespace dayflux
