// The core's sampling helpers against their definitions, and the CPU caster's refined triangle
// hits (on the triangle, inside it, at the ray's point, however near an edge or grazing the ray)
// and its blockers (never the object a ray leaves, as in the walk).
#include "raytrace/core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "raytrace/backend.h"
#include "raytrace/core/shapes.h"
#include "scene/reader.h"

namespace dayflux::test {
namespace {

using core::real3;

FlatScene SceneOf(const std::string &text, const char *name) {
    Scene scene;
    SceneReader(&scene).ReadText(text, name);
    return Flatten(std::move(scene));
}

// The CPU caster of flat, with every triangle a blocker.
std::unique_ptr<Backend> CasterBlockedByAll(const FlatScene &flat) {
    std::unique_ptr<Backend> caster = CreateEmbreeBackend();
    std::vector<uint32_t> all(flat.triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    caster->SetBlockers(all);
    caster->Commit(flat);
    return caster;
}

// Within two units in the last place of libm's double sin and cos over the whole interval.
TEST(Sampling, SinCosQuarterIsLibmsToTheLastBits) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-M_PI / 4, M_PI / 4);
    for (int i = 0; i < 200000; ++i) {
        const double x = i == 0 ? M_PI / 4 : i == 1 ? -M_PI / 4 : i == 2 ? 0 : u(rng);
        double s, c;
        core::SinCosQuarter(x, s, c);
        ASSERT_LE(std::abs(s - std::sin(x)),
                  2 * std::abs(std::nextafter(std::sin(x), 2.0) - std::sin(x)))
            << x;
        ASSERT_LE(std::abs(c - std::cos(x)), 2 * (std::nextafter(std::cos(x), 2.0) - std::cos(x)))
            << x;
    }
}

// Orthonormal and right-handed (v = n x u) for any unit normal, the poles and near the south
// pole (where Frisvad's first form lost its precision) included.
TEST(Sampling, TangentsAreAnOrthonormalFrame) {
    std::mt19937_64 rng(4);
    std::normal_distribution<double> g;
    std::vector<real3> normals = {real3(0, 0, 1), real3(0, 0, -1), real3(1, 0, 0), real3(0, -1, 0),
                                  glm::normalize(real3(1e-9, 2e-9, -1))};
    for (int i = 0; i < 100000; ++i)
        normals.push_back(glm::normalize(real3(g(rng), g(rng), g(rng))));
    for (const real3 &n : normals) {
        real3 u, v;
        core::Tangents(n, u, v);
        ASSERT_NEAR(glm::dot(u, u), 1, 1e-14);
        ASSERT_NEAR(glm::dot(v, v), 1, 1e-14);
        ASSERT_NEAR(glm::dot(u, v), 0, 1e-14);
        ASSERT_NEAR(glm::dot(u, n), 0, 1e-14);
        ASSERT_NEAR(glm::dot(v, n), 0, 1e-14);
        ASSERT_LT(glm::length(glm::cross(n, u) - v), 1e-14);
    }
}

// A tilted triangle 1000 m from the origin in a scene 40 m across, and rays from everywhere
// (up to 40 km away) aimed at points of it: uniformly over it, a hair inside and outside its
// edges, and at grazing angles down to 1e-5 radians. Every hit Embree reports is refined onto the
// triangle's plane and into the triangle, and where the refined point needed no moving it is the
// ray's own point.
TEST(Sampling, RefinedTriangleHitsLieOnTheTriangle) {
    const real3 a(1000, 2000, 3), b(1013, 2004, 9), c(1002, 2011, -2);
    std::ostringstream text;
    text.precision(17);
    text << "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
         << "grey polygon t 0 0 9 " << a.x << ' ' << a.y << ' ' << a.z << ' ' << b.x << ' ' << b.y
         << ' ' << b.z << ' ' << c.x << ' ' << c.y << ' ' << c.z << '\n'
         << "grey sphere far 0 0 4 1030 2030 10 .5\n";  // the scene's extent: about 40 m
    const FlatScene flat = SceneOf(text.str(), "triangle.rad");
    const std::unique_ptr<Backend> caster = CreateEmbreeBackend();
    caster->Commit(flat);
    const real3 n = glm::normalize(glm::cross(b - a, c - a));
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u01(0, 1);
    int hits = 0, near_edge = 0;
    for (int i = 0; i < 200000; ++i) {
        // A target: barycentrics uniform, or within 1e-9 .. 1e-3 of an edge on either side.
        double s = u01(rng), t = u01(rng);
        if (s + t > 1) s = 1 - s, t = 1 - t;
        if (i % 2 == 1) {
            const double off = std::pow(10, -9 + 6 * u01(rng)) * (u01(rng) < .5 ? -1 : 1);
            const int edge = i % 6 / 2;
            if (edge == 0) s = off;
            if (edge == 1) t = off;
            if (edge == 2) t = 1 - s - off;
        }
        const real3 target = a + s * (b - a) + t * (c - a);
        // A direction: uniform over the sphere, or grazing the plane by 1e-5 .. 1e-1 radians.
        real3 dir = glm::normalize(real3(u01(rng) - .5, u01(rng) - .5, u01(rng) - .5));
        if (i % 3 == 0) {
            const real3 along = glm::normalize(dir - glm::dot(dir, n) * n);
            const double angle = std::pow(10, -5 + 4 * u01(rng));
            dir = std::cos(angle) * along + std::sin(angle) * (u01(rng) < .5 ? -n : n);
        }
        // from within the scene, or from 100 to 1000 times its size away (the float ray's error
        // grows with its origin's distance from the centre)
        const double back = i % 5 == 4 ? 40 * std::pow(10, 2 + u01(rng)) : 0.5 + 20 * u01(rng);
        TraceRay ray;
        for (int k = 0; k < 3; ++k) ray.org[k] = target[k] - back * dir[k], ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        TraceHit hit;
        caster->Closest(&ray, &hit, 1);
        if (!hit.hit || hit.shape >= 0) continue;
        ++hits;
        const real3 p(hit.point[0], hit.point[1], hit.point[2]);
        const real3 org(ray.org[0], ray.org[1], ray.org[2]);
        // the rounding of org + t dir, about 2000 m from the world's origin and 40 km away
        const double tolerance = 1e-11 + 1e-15 * (glm::length(org) + hit.t);
        ASSERT_LT(std::abs(glm::dot(p - a, n)), tolerance) << i;
        ASSERT_LT(glm::length(core::ClosestPointOnTriangle(p, a, b, c) - p), tolerance) << i;
        if (glm::length(org + hit.t * dir - p) > tolerance)
            ++near_edge;  // moved in: a hit a hair outside
    }
    EXPECT_GT(hits, 150000);
    EXPECT_GT(near_edge, 0);  // the float traversal does report hits beyond an edge
}

// Closest's rays traced together (Embree's packets of eight, through the scene without its
// filter, and again through the filtered one where a ray met its own object) meet what each
// meets alone: the same triangle or analytic surface at the same point, never the polygon a ray
// leaves however it grazes it; from a box's walls, a bent polygon, a sphere, and from nowhere.
TEST(Sampling, PacketsMeetWhatRaysAloneMeet) {
    const std::string text =
        "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
        "grey polygon floor 0 0 12 0 0 0  0 4 0  4 4 0  4 0 0\n"
        "grey polygon ceiling 0 0 12 0 0 3  4 0 3  4 4 3  0 4 3\n"
        "grey polygon west 0 0 12 0 0 0  0 0 3  0 4 3  0 4 0\n"
        "grey polygon east 0 0 12 4 0 0  4 4 0  4 4 3  4 0 3\n"
        "grey polygon north 0 0 12 0 4 0  0 4 3  4 4 3  4 4 0\n"
        "grey polygon south 0 0 12 0 0 0  4 0 0  4 0 3  0 0 3\n"
        "grey polygon bent 0 0 18 1 1 1.5  3 1 1.5  3 2 1  3 3 1.5  1 3 1.5  1 2 1\n"
        "grey sphere ball 0 0 4 3 3 .6 .4\n"
        "grey cone hat 0 0 8 1 3 .2  1 3 1  .3 .1\n";
    const FlatScene flat = SceneOf(text, "packets.rad");
    const std::unique_ptr<Backend> caster = CreateEmbreeBackend();
    caster->Commit(flat);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u01(0, 1);
    auto unit = [&] { return glm::normalize(real3(u01(rng) - .5, u01(rng) - .5, u01(rng) - .5)); };
    int ball = -1;
    for (const auto &shape : flat.shapes)
        if (shape.kind == AnalyticShape::kSphere) ball = shape.object;
    ASSERT_GE(ball, 0);
    std::vector<TraceRay> rays;
    for (int i = 0; i < 40000; ++i) {
        real3 org, dir = unit();
        int from = -1;
        if (i % 4 < 2) {  // from a triangle of a wall or of the bent polygon
            const size_t t = rng() % flat.triangles.size();
            double a = u01(rng), b = u01(rng);
            if (a + b > 1) a = 1 - a, b = 1 - b;
            const Vec3 &p = flat.vertices[flat.triangles[t][0]],
                       &q = flat.vertices[flat.triangles[t][1]],
                       &r = flat.vertices[flat.triangles[t][2]];
            for (int k = 0; k < 3; ++k) org[k] = p[k] + a * (q[k] - p[k]) + b * (r[k] - p[k]);
            from = flat.triangle_object[t];
            if (i % 4 == 1) {  // grazing it by 1e-7 .. 1e-2 radians
                const real3 n =
                    glm::normalize(glm::cross(real3(q[0] - p[0], q[1] - p[1], q[2] - p[2]),
                                              real3(r[0] - p[0], r[1] - p[1], r[2] - p[2])));
                const real3 along = glm::normalize(dir - glm::dot(dir, n) * n);
                const double angle = std::pow(10, -7 + 5 * u01(rng));
                dir = std::cos(angle) * along + std::sin(angle) * (u01(rng) < .5 ? -n : n);
            }
        } else if (i % 4 == 2) {  // from the sphere, out of it or into it
            const real3 n = unit();
            org = real3(3, 3, .6) + .4 * n;
            from = ball;
        } else {
            org = real3(.2 + 3.6 * u01(rng), .2 + 3.6 * u01(rng), .2 + 2.6 * u01(rng));
        }
        TraceRay ray;
        for (int k = 0; k < 3; ++k) ray.org[k] = org[k], ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        ray.from_object = from;
        rays.push_back(ray);
    }
    std::vector<TraceHit> together(rays.size());
    caster->Closest(rays.data(), together.data(), rays.size());
    int hits = 0, shapes = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        TraceHit alone;
        caster->Closest(&rays[i], &alone, 1);
        const TraceHit &h = together[i];
        ASSERT_EQ(h.hit, alone.hit) << i;
        if (!h.hit) continue;
        ++hits;
        ASSERT_EQ(h.shape, alone.shape) << i;
        if (h.shape >= 0) {
            ++shapes;
        } else {
            ASSERT_EQ(h.triangle, alone.triangle) << i;
            // a polygon is never met by its own rays
            ASSERT_NE(flat.triangle_object[h.triangle], rays[i].from_object) << i;
        }
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(h.point[k], alone.point[k], 1e-12) << i;
    }
    EXPECT_GT(hits, 30000);  // a closed box: all but the walls' rays outward meet something
    EXPECT_GT(shapes, 2000);
    // a scene of analytic surfaces alone: rays that miss them are misses, alone or together
    const FlatScene ball_alone = SceneOf(
        "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
        "grey sphere ball 0 0 4 0 0 0 1\n",
        "ball.rad");
    const std::unique_ptr<Backend> ball_caster = CreateEmbreeBackend();
    ball_caster->Commit(ball_alone);
    std::vector<TraceRay> at_ball;
    for (int i = 0; i < 64; ++i) {
        TraceRay ray;
        const real3 dir = unit();
        for (int k = 0; k < 3; ++k) ray.org[k] = k == 0 ? 5 : 0, ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        at_ball.push_back(ray);
    }
    std::vector<TraceHit> ball_hits(at_ball.size());
    ball_caster->Closest(at_ball.data(), ball_hits.data(), at_ball.size());
    int met = 0;
    for (size_t i = 0; i < at_ball.size(); ++i) {
        TraceHit alone;
        ball_caster->Closest(&at_ball[i], &alone, 1);
        ASSERT_EQ(ball_hits[i].hit, alone.hit) << i;
        // toward the ball (x < 0) within its angle (sin 1/5) from 5 m away
        ASSERT_EQ(alone.hit, at_ball[i].dir[0] < -std::sqrt(1 - 1. / 25)) << i;
        met += alone.hit;
    }
    EXPECT_LT(met, 64);
}

// Blocked keeps Closest's rule for the object a ray leaves: a flat polygon is never met by its
// own rays, however they graze it (they start past where float rounding could put it), nor is a
// bent polygon (its triangles in different planes: the filtered blockers), whose rays cross from
// one of its triangles to another; rays from either toward the other are blocked.
TEST(Sampling, BlockersNeverMeetTheObjectARayLeaves) {
    const std::string text =
        "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
        "grey polygon flat 0 0 12 1000 2000 0  1010 2000 0  1010 2010 0  1000 2010 0\n"
        "grey polygon bent 0 0 18 1002 2002 1.5  1008 2002 1.5  1008 2005 .5  1008 2008 1.5"
        "  1002 2008 1.5  1002 2005 .5\n";
    const FlatScene flat = SceneOf(text, "blockers.rad");
    const std::unique_ptr<Backend> caster = CasterBlockedByAll(flat);
    auto centroid = [&](size_t i) {
        real3 c(0);
        for (int k = 0; k < 3; ++k) {
            const Vec3 &v = flat.vertices[flat.triangles[i][k]];
            c += real3(v[0], v[1], v[2]) / 3.0;
        }
        return c;
    };
    auto blocked = [&](real3 org, real3 dir, int from) {
        TraceRay ray;
        for (int k = 0; k < 3; ++k) ray.org[k] = org[k], ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        ray.from_object = from;
        bool b = true;
        caster->Blocked(&ray, &b, 1);
        return b;
    };
    const int flat_object = flat.triangle_object[0];
    std::vector<size_t> bent;
    for (size_t i = 0; i < flat.triangles.size(); ++i)
        if (flat.triangle_object[i] != flat_object) bent.push_back(i);
    ASSERT_GE(bent.size(), 4u);
    // the flat one's own rays, grazing it by 1e-6 .. 1e-2 radians (passing under the bent one)
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int i = 0; i < 20000; ++i) {
        const real3 org(1000 + 10 * u01(rng), 2000 + 10 * u01(rng), 0);
        const double azimuth = 2 * M_PI * u01(rng), angle = std::pow(10, -6 + 4 * u01(rng));
        const real3 dir(std::cos(angle) * std::cos(azimuth), std::cos(angle) * std::sin(azimuth),
                        (i % 2 ? 1 : -1) * std::sin(angle));
        ASSERT_FALSE(blocked(org, dir, flat_object)) << i;
    }
    // the bent one's rays from each of its triangles to each other one: never blocked by it
    int crossed = 0;
    for (size_t i : bent)
        for (size_t j : bent) {
            if (i == j) continue;
            const real3 from = centroid(i), dir = glm::normalize(centroid(j) - from);
            if (dir.z < 0) continue;  // not toward the flat one below
            ++crossed;
            EXPECT_FALSE(blocked(from, dir, flat.triangle_object[i])) << i << " to " << j;
        }
    EXPECT_GT(crossed, 0);
    // and between the two, both ways
    for (size_t i : bent) {
        const real3 c = centroid(i), below(c.x, c.y, 0);
        EXPECT_TRUE(blocked(c, real3(0, 0, -1), flat.triangle_object[i])) << i;
        EXPECT_TRUE(blocked(below, real3(0, 0, 1), flat_object)) << i;
    }
    // A tilted 400-sided disc near the origin, triangulated as a fan of slivers (0.9 degrees),
    // whose float normals are further off than a square's: its grazing rays do not meet it.
    {
        std::ostringstream disc;
        disc.precision(17);
        const real3 n = glm::normalize(real3(.3, .5, .81)),
                    ax = glm::normalize(glm::cross(n, real3(1, 0, 0))), ay = glm::cross(n, ax),
                    centre(3, -2, 1);
        disc << "void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey polygon disc 0 0 1200";
        for (int i = 0; i < 400; ++i) {
            const double a = 2 * M_PI * i / 400;
            const real3 p = centre + 5 * std::cos(a) * ax + 5 * std::sin(a) * ay;
            disc << ' ' << p.x << ' ' << p.y << ' ' << p.z;
        }
        const FlatScene disc_flat = SceneOf(disc.str() + "\n", "disc.rad");
        const std::unique_ptr<Backend> disc_caster = CasterBlockedByAll(disc_flat);
        for (int i = 0; i < 40000; ++i) {
            const auto &t = disc_flat.triangles[i % disc_flat.triangles.size()];
            double s = u01(rng), r = u01(rng);
            if (s + r > 1) s = 1 - s, r = 1 - r;
            auto vertex = [&](int k) {
                const Vec3 &v = disc_flat.vertices[t[k]];
                return real3(v[0], v[1], v[2]);
            };
            const real3 org = vertex(0) + s * (vertex(1) - vertex(0)) + r * (vertex(2) - vertex(0));
            const double azimuth = 2 * M_PI * u01(rng), angle = std::pow(10, -5 + 2 * u01(rng));
            const real3 dir = std::cos(angle) * (std::cos(azimuth) * ax + std::sin(azimuth) * ay) +
                              (i % 2 ? 1 : -1) * std::sin(angle) * n;
            TraceRay ray;
            for (int k = 0; k < 3; ++k) ray.org[k] = org[k], ray.dir[k] = dir[k];
            ray.tmax = INFINITY;
            ray.from_object = disc_flat.triangle_object[0];
            bool b = true;
            disc_caster->Blocked(&ray, &b, 1);
            ASSERT_FALSE(b) << i;
        }
    }
    // Asked many at once (in packets where they may be), the answers are those asked one by one:
    // rays from the flat one, from the bent one and from nothing, every way.
    std::vector<TraceRay> rays;
    std::vector<char> alone;
    for (int i = 0; i < 3000; ++i) {
        const int kind = i % 3;
        const size_t t = bent[i % bent.size()];
        const real3 org = kind == 0   ? real3(1000 + 10 * u01(rng), 2000 + 10 * u01(rng), 0)
                          : kind == 1 ? centroid(t)
                                      : real3(1005, 2005, 5) + 3.0 * real3(u01(rng), u01(rng), 0);
        const real3 dir = glm::normalize(real3(u01(rng) - .5, u01(rng) - .5, u01(rng) - .5));
        TraceRay ray;
        for (int k = 0; k < 3; ++k) ray.org[k] = org[k], ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        ray.from_object = kind == 0 ? flat_object : kind == 1 ? flat.triangle_object[t] : -1;
        rays.push_back(ray);
        alone.push_back(blocked(org, dir, ray.from_object));
    }
    std::unique_ptr<bool[]> together(new bool[rays.size()]);
    caster->Blocked(rays.data(), together.get(), rays.size());
    int some = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(together[i], alone[i] != 0) << i;
        some += together[i];
    }
    EXPECT_GT(some, 300);
    EXPECT_LT(some, 2700);
}

}  // namespace
}  // namespace dayflux::test
