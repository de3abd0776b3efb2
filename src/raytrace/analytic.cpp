#include "raytrace/analytic.h"

#include <algorithm>
#include <cmath>

namespace dayflux {

namespace {

double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Axis frame of a cone or cylinder: base point, unit axis, length, radius slope.
struct Axis {
    double base[3], u[3], length, r0, slope;
};

Axis MakeAxis(const AnalyticShape &s, const double offset[3]) {
    Axis a;
    double d[3];
    for (int k = 0; k < 3; ++k) a.base[k] = s.p0[k] - offset[k], d[k] = s.p1[k] - s.p0[k];
    a.length = std::sqrt(Dot(d, d));
    for (int k = 0; k < 3; ++k) a.u[k] = d[k] / a.length;
    a.r0 = s.r0;
    a.slope = (s.r1 - s.r0) / a.length;
    return a;
}

// Roots of a t^2 + b t + c = 0 in increasing order; false if none.
bool Quadratic(double a, double b, double c, double *t0, double *t1) {
    if (std::fabs(a) < 1e-300) {
        if (std::fabs(b) < 1e-300) return false;
        *t0 = *t1 = -c / b;
        return true;
    }
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return false;
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    double x0 = q / a, x1 = q != 0 ? c / q : x0;
    if (x0 > x1) std::swap(x0, x1);
    *t0 = x0, *t1 = x1;
    return true;
}

}  // namespace

double IntersectShape(const AnalyticShape &s, const double offset[3], const double org[3],
                      const double dir[3], double tmin, double tmax) {
    switch (s.kind) {
        case AnalyticShape::kSphere: {
            double oc[3];
            for (int k = 0; k < 3; ++k) oc[k] = org[k] - (s.p0[k] - offset[k]);
            double t0, t1;
            if (!Quadratic(1.0, 2 * Dot(oc, dir), Dot(oc, oc) - s.r0 * s.r0, &t0, &t1)) return -1;
            if (t0 > tmin && t0 < tmax) return t0;
            if (t1 > tmin && t1 < tmax) return t1;
            return -1;
        }
        case AnalyticShape::kRing: {
            double n[3] = {s.p1[0], s.p1[1], s.p1[2]};
            const double len = std::sqrt(Dot(n, n));
            for (double &x : n) x /= len;
            const double dn = Dot(dir, n);
            if (std::fabs(dn) < 1e-300) return -1;
            double c[3];
            for (int k = 0; k < 3; ++k) c[k] = s.p0[k] - offset[k] - org[k];
            const double t = Dot(c, n) / dn;
            if (!(t > tmin && t < tmax)) return -1;
            double r2 = 0;
            for (int k = 0; k < 3; ++k) {
                const double x = org[k] + t * dir[k] - (s.p0[k] - offset[k]);
                r2 += x * x;
            }
            return r2 >= s.r0 * s.r0 && r2 <= s.r1 * s.r1 ? t : -1;
        }
        case AnalyticShape::kCone:
        case AnalyticShape::kCylinder: {
            const Axis a = MakeAxis(s, offset);
            double w[3];
            for (int k = 0; k < 3; ++k) w[k] = org[k] - a.base[k];
            const double wu = Dot(w, a.u), du = Dot(dir, a.u);
            double wp[3], dp[3];
            for (int k = 0; k < 3; ++k) wp[k] = w[k] - wu * a.u[k], dp[k] = dir[k] - du * a.u[k];
            // |wp + t dp|^2 = (r0 + slope (wu + t du))^2
            const double rw = a.r0 + a.slope * wu, rd = a.slope * du;
            double t0, t1;
            if (!Quadratic(Dot(dp, dp) - rd * rd, 2 * (Dot(wp, dp) - rw * rd),
                           Dot(wp, wp) - rw * rw, &t0, &t1))
                return -1;
            for (double t : {t0, t1}) {
                if (!(t > tmin && t < tmax)) continue;
                const double z = wu + t * du;
                if (z < 0 || z > a.length || a.r0 + a.slope * z < 0) continue;
                return t;
            }
            return -1;
        }
        case AnalyticShape::kSource:
            return -1;
    }
    return -1;
}

void ShapeNormal(const AnalyticShape &s, const double offset[3], const double p[3],
                 double normal[3]) {
    double n[3] = {0, 0, 1};
    switch (s.kind) {
        case AnalyticShape::kSphere:
            for (int k = 0; k < 3; ++k) n[k] = p[k] - (s.p0[k] - offset[k]);
            break;
        case AnalyticShape::kRing:
            for (int k = 0; k < 3; ++k) n[k] = s.p1[k];
            break;
        case AnalyticShape::kCone:
        case AnalyticShape::kCylinder: {
            // Outward: the radial direction tilted back by the radius' slope along the axis.
            const Axis a = MakeAxis(s, offset);
            double w[3];
            for (int k = 0; k < 3; ++k) w[k] = p[k] - a.base[k];
            const double wu = Dot(w, a.u);
            double radial[3];
            for (int k = 0; k < 3; ++k) radial[k] = w[k] - wu * a.u[k];
            const double rl = std::sqrt(Dot(radial, radial));
            for (int k = 0; k < 3; ++k) n[k] = (rl > 0 ? radial[k] / rl : 0) - a.slope * a.u[k];
            break;
        }
        case AnalyticShape::kSource:
            break;
    }
    const double len = std::sqrt(Dot(n, n));
    const double sign = s.inward ? -1 : 1;
    for (int k = 0; k < 3; ++k) normal[k] = len > 0 ? sign * n[k] / len : 0;
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
