#include "raytrace/analytic.h"

#include <algorithm>
#include <cmath>

#include "raytrace/core/shapes.h"

namespace dayflux {

int CoreShapeKind(AnalyticShape::Kind kind) {
    switch (kind) {
        case AnalyticShape::kSphere:
            return core::kShapeSphere;
        case AnalyticShape::kCone:
            return core::kShapeCone;
        case AnalyticShape::kCylinder:
            return core::kShapeCylinder;
        default:
            return core::kShapeRing;
    }
}

namespace {

// The shape's ends (or centre and normal), recentred by offset; a ring's normal stays.
void Ends(const AnalyticShape &s, const double offset[3], core::real3 *p0, core::real3 *p1) {
    for (int k = 0; k < 3; ++k) {
        (*p0)[k] = s.p0[k] - offset[k];
        (*p1)[k] = s.kind == AnalyticShape::kRing ? s.p1[k] : s.p1[k] - offset[k];
    }
}

}  // namespace

double IntersectShape(const AnalyticShape &s, const double offset[3], const double org[3],
                      const double dir[3], double tmin, double tmax) {
    if (s.kind == AnalyticShape::kSource) return -1;
    core::real3 p0, p1;
    Ends(s, offset, &p0, &p1);
    return core::IntersectShape(CoreShapeKind(s.kind), p0, s.r0, p1, s.r1,
                                core::real3(org[0], org[1], org[2]),
                                core::real3(dir[0], dir[1], dir[2]), tmin, tmax);
}

void ShapeNormal(const AnalyticShape &s, const double offset[3], const double p[3],
                 double normal[3]) {
    core::real3 p0, p1, n(0);
    if (s.kind != AnalyticShape::kSource) {
        Ends(s, offset, &p0, &p1);
        n = core::ShapeNormal(CoreShapeKind(s.kind), s.inward, p0, s.r0, p1, s.r1,
                              core::real3(p[0], p[1], p[2]));
    }
    for (int k = 0; k < 3; ++k) normal[k] = n[k];
}

void ShapeBounds(const AnalyticShape &s, const double offset[3], double lo[3], double hi[3]) {
    for (int k = 0; k < 3; ++k) {
        const double c0 = s.p0[k] - offset[k];
        switch (s.kind) {
            case AnalyticShape::kSphere:
                lo[k] = c0 - s.r0, hi[k] = c0 + s.r0;
                break;
            case AnalyticShape::kRing:
                lo[k] = c0 - s.r1, hi[k] = c0 + s.r1;
                break;
            case AnalyticShape::kCone:
            case AnalyticShape::kCylinder: {
                const double c1 = s.p1[k] - offset[k];
                lo[k] = std::min(c0 - s.r0, c1 - s.r1), hi[k] = std::max(c0 + s.r0, c1 + s.r1);
                break;
            }
            case AnalyticShape::kSource:
                lo[k] = hi[k] = 0;
                break;
        }
    }
}

}  // namespace dayflux
