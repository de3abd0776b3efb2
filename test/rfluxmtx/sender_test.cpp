#include "rfluxmtx/sender.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>
#include <utility>

namespace dayflux {
namespace {

// Every point of the curve once, each a unit step from the one before.
TEST(HilbertCoordinates, VisitsEveryCellOnceByUnitSteps) {
    for (int n : {2, 3}) {
        const int nbits = 4;
        std::set<std::vector<uint64_t>> seen;
        uint64_t prev[3] = {0, 0, 0};
        for (uint64_t i = 0; i < (uint64_t{1} << (n * nbits)); ++i) {
            uint64_t x[3] = {0, 0, 0};
            HilbertCoordinates(n, nbits, i, x);
            for (int k = 0; k < n; ++k) ASSERT_LT(x[k], uint64_t{1} << nbits);
            EXPECT_TRUE(seen.insert(std::vector<uint64_t>(x, x + n)).second) << n << " " << i;
            if (i > 0) {
                int steps = 0;
                for (int k = 0; k < n; ++k)
                    steps += std::abs(static_cast<int>(x[k]) - static_cast<int>(prev[k]));
                EXPECT_EQ(steps, 1) << "n " << n << " index " << i;
            }
            std::copy(x, x + n, prev);
        }
        EXPECT_EQ(seen.size(), size_t{1} << (n * nbits));
    }
}

FluxGroup Square(FluxBasis::Kind kind, int size) {
    FluxGroup g;
    g.modifier = "void";
    g.has_basis = true;
    g.basis.kind = kind;
    g.basis.size = size;
    FluxSurface s;
    s.type = FluxSurface::kPolygon;
    s.name = "w";
    s.args = {0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0};  // facing -Z
    s.normal[0] = s.normal[1] = 0, s.normal[2] = -1;
    s.area = 1;
    g.surfaces.push_back(s);
    return g;
}

// The sender's rays: `samples` per bin, in bin order, from the square, leaving its back.
TEST(SenderSampler, GivesEachBinItsSamplesFromTheSurface) {
    const FluxGroup g = Square(FluxBasis::kKlemsQuarter, 1);
    SenderSampler sampler(g, 7, 1);
    ASSERT_EQ(sampler.Bins(), 41);
    double ray[6];
    int count = 0;
    while (sampler.Next(ray)) {
        ++count;
        EXPECT_GE(ray[0], 0);
        EXPECT_LE(ray[0], 1);
        EXPECT_GE(ray[1], 0);
        EXPECT_LE(ray[1], 1);
        EXPECT_EQ(ray[2], 0);
        EXPECT_GT(ray[5], 0);
        EXPECT_NEAR(ray[3] * ray[3] + ray[4] * ray[4] + ray[5] * ray[5], 1, 1e-12);
    }
    EXPECT_EQ(count, 41 * 7);
}

TEST(SenderSampler, SameSeedSameRays) {
    const FluxGroup g = Square(FluxBasis::kReinhart, 2);
    SenderSampler a(g, 3, 5), b(g, 3, 5), c(g, 3, 6);
    EXPECT_EQ(a.Bins(), 577);
    double ra[6], rb[6], rc[6];
    bool differs = false;
    while (a.Next(ra)) {
        ASSERT_TRUE(b.Next(rb));
        ASSERT_TRUE(c.Next(rc));
        for (int k = 0; k < 6; ++k) EXPECT_EQ(ra[k], rb[k]);
        differs = differs || ra[3] != rc[3];
    }
    EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace dayflux
