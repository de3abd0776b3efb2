// Ray intersections with analytic surfaces, against hand-computed distances and normals.
#include "raytrace/analytic.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dayflux {
namespace {

const double kNoOffset[3] = {0, 0, 0};

TEST(AnalyticShapes, SphereFromOutsideAndInside) {
    AnalyticShape s{AnalyticShape::kSphere};
    s.p0 = {1, 2, 3};
    s.r0 = 2;
    const double org[3] = {1, 2, -5}, up[3] = {0, 0, 1};
    EXPECT_DOUBLE_EQ(IntersectShape(s, kNoOffset, org, up, 1e-9, 1e30), 6);
    const double inside[3] = {1, 2, 3};
    EXPECT_DOUBLE_EQ(IntersectShape(s, kNoOffset, inside, up, 1e-9, 1e30), 2);
    EXPECT_LT(IntersectShape(s, kNoOffset, org, up, 1e-9, 5.5), 0);  // beyond tmax
    double n[3];
    const double p[3] = {1, 2, 1};
    ShapeNormal(s, kNoOffset, p, n);
    EXPECT_DOUBLE_EQ(n[2], -1);
    s.inward = true;  // bubble
    ShapeNormal(s, kNoOffset, p, n);
    EXPECT_DOUBLE_EQ(n[2], 1);
    // Recentring moves the shape with the ray.
    const double offset[3] = {1e6, 0, 0}, far[3] = {1 - 1e6, 2, -5};
    EXPECT_NEAR(IntersectShape(s, offset, far, up, 1e-9, 1e30), 6, 1e-9);
}

TEST(AnalyticShapes, RingIsAnnulus) {
    AnalyticShape s{AnalyticShape::kRing};
    s.p0 = {0, 0, 2};
    s.p1 = {0, 0, 3};  // normal, any length
    s.r0 = 1, s.r1 = 2;
    const double up[3] = {0, 0, 1};
    const double through_hole[3] = {0.5, 0, 0}, on_ring[3] = {1.5, 0, 0}, outside[3] = {2.5, 0, 0};
    EXPECT_LT(IntersectShape(s, kNoOffset, through_hole, up, 1e-9, 1e30), 0);
    EXPECT_DOUBLE_EQ(IntersectShape(s, kNoOffset, on_ring, up, 1e-9, 1e30), 2);
    EXPECT_LT(IntersectShape(s, kNoOffset, outside, up, 1e-9, 1e30), 0);
    double n[3];
    ShapeNormal(s, kNoOffset, on_ring, n);
    EXPECT_DOUBLE_EQ(n[2], 1);
}

TEST(AnalyticShapes, CylinderAndCone) {
    AnalyticShape c{AnalyticShape::kCylinder};
    c.p0 = {0, 0, 0}, c.p1 = {0, 0, 4};
    c.r0 = c.r1 = 1;
    const double org[3] = {-5, 0, 1}, east[3] = {1, 0, 0};
    EXPECT_NEAR(IntersectShape(c, kNoOffset, org, east, 1e-9, 1e30), 4, 1e-12);
    const double above[3] = {-5, 0, 5};
    EXPECT_LT(IntersectShape(c, kNoOffset, above, east, 1e-9, 1e30), 0);  // past its end
    const double axis[3] = {0, 0, 2};
    EXPECT_NEAR(IntersectShape(c, kNoOffset, axis, east, 1e-9, 1e30), 1, 1e-12);  // inside
    // A cone from radius 2 at z = 0 to 0 at z = 2: at height 1 the radius is 1.
    AnalyticShape k{AnalyticShape::kCone};
    k.p0 = {0, 0, 0}, k.p1 = {0, 0, 2};
    k.r0 = 2, k.r1 = 0;
    EXPECT_NEAR(IntersectShape(k, kNoOffset, org, east, 1e-9, 1e30), 4, 1e-12);
    double n[3];
    const double p[3] = {-1, 0, 1};
    ShapeNormal(k, kNoOffset, p, n);  // outward and up at 45 degrees
    EXPECT_NEAR(n[0], -std::sqrt(.5), 1e-12);
    EXPECT_NEAR(n[2], std::sqrt(.5), 1e-12);
}

}  // namespace
}  // namespace dayflux
