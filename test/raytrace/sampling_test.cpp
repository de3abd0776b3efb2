// The core's sampling helpers against their definitions, and the CPU caster's refined triangle
// hits: on the triangle, inside it, at the ray's point, however near an edge or grazing the ray.
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
// aimed at points of it: uniformly over it, a hair inside and outside its edges, and at grazing
// angles down to 1e-5 radians. Every hit Embree reports is refined onto the triangle's plane
// and into the triangle, and where the refined point needed no moving it is the ray's own point.
TEST(Sampling, RefinedTriangleHitsLieOnTheTriangle) {
    const real3 a(1000, 2000, 3), b(1013, 2004, 9), c(1002, 2011, -2);
    std::ostringstream text;
    text.precision(17);
    text << "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
         << "grey polygon t 0 0 9 " << a.x << ' ' << a.y << ' ' << a.z << ' ' << b.x << ' ' << b.y
         << ' ' << b.z << ' ' << c.x << ' ' << c.y << ' ' << c.z << '\n'
         << "grey sphere far 0 0 4 1030 2030 10 .5\n";  // the scene's extent: about 40 m
    Scene scene;
    SceneReader(&scene).ReadText(text.str(), "triangle.rad");
    const FlatScene flat = Flatten(std::move(scene));
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
        const double back = 0.5 + 20 * u01(rng);
        TraceRay ray;
        for (int k = 0; k < 3; ++k) ray.org[k] = target[k] - back * dir[k], ray.dir[k] = dir[k];
        ray.tmax = INFINITY;
        TraceHit hit;
        caster->Closest(&ray, &hit, 1);
        if (!hit.hit || hit.shape >= 0) continue;
        ++hits;
        const real3 p(hit.point[0], hit.point[1], hit.point[2]);
        ASSERT_LT(std::abs(glm::dot(p - a, n)), 1e-11) << i;
        ASSERT_LT(glm::length(core::ClosestPointOnTriangle(p, a, b, c) - p), 1e-11) << i;
        const real3 on_ray = real3(ray.org[0], ray.org[1], ray.org[2]) + hit.t * dir;
        if (glm::length(on_ray - p) > 1e-11) ++near_edge;  // moved in: a hit a hair outside
    }
    EXPECT_GT(hits, 150000);
    EXPECT_GT(near_edge, 0);  // the float traversal does report hits beyond an edge
}

}  // namespace
}  // namespace dayflux::test
