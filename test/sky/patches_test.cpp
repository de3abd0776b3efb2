#include "sky/patches.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sky/solar.h"

namespace dayflux {
namespace {

TEST(SkyPatchBasis, CountsAndSolidAnglesSumToTwoPi) {
    for (int mf = 1; mf <= 6; ++mf) {
        SkyPatchBasis b(mf);
        ASSERT_EQ(b.Size(), 144 * mf * mf + 2);
        double sum = 0;
        for (int p = 1; p < b.Size(); ++p) sum += b.SolidAngle(p);
        // Each solid angle is stored in float, as gendaymtx stores it.
        EXPECT_NEAR(sum, 2 * M_PI, 2 * M_PI * 1e-6) << "MF " << mf;
        EXPECT_FLOAT_EQ(b.SolidAngle(0), static_cast<float>(2 * M_PI));
    }
}

// A uniform sky of radiance 1 gives horizontal irradiance pi; the patch sum is the midpoint rule
// for the integral of cos(zenith) over each row, exact to O(row height^2).
TEST(SkyPatchBasis, UniformSkyGivesPiOnTheHorizontal) {
    for (int mf = 1; mf <= 6; ++mf) {
        SkyPatchBasis b(mf);
        double e = 0;
        for (int p = 1; p < b.Size(); ++p)
            e += std::sin(static_cast<double>(b.Altitude(p))) * b.SolidAngle(p);
        const double h = b.RowHeight();
        EXPECT_NEAR(e, M_PI, M_PI * h * h / 4) << "MF " << mf;
    }
}

TEST(SkyPatchBasis, BinsFollowReinhartCal) {
    SkyPatchBasis t(1);  // Tregenza
    auto dir = [](double alt_deg, double azi_deg, double v[3]) {
        const double a = alt_deg * M_PI / 180, z = azi_deg * M_PI / 180;
        v[0] = std::cos(a) * std::sin(z);  // east
        v[1] = std::cos(a) * std::cos(z);  // north
        v[2] = std::sin(a);
    };
    double v[3];
    dir(6, 0, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 1);  // north at the horizon
    dir(6, 12, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 2);  // next patch is east of north
    dir(6, 354, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 1);  // patch 1 straddles north
    dir(6, 345, v);                         // patch 30 covers 342..354 degrees
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 30);
    dir(18, 0, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 31);
    dir(89, 0, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 145);
    dir(-5, 0, v);
    EXPECT_EQ(t.Bin(v[0], v[1], v[2]), 0);
    for (int mf = 1; mf <= 6; ++mf) {
        SkyPatchBasis b(mf);
        for (int p = 1; p < b.Size(); ++p) {
            b.Direction(p, v);
            ASSERT_EQ(b.Bin(v[0], v[1], v[2]), p) << "MF " << mf;
        }
    }
}

TEST(Solar, TableCosineIsRadiancesApproximation) {
    // Nearest of 1024 entries per quarter turn: within half a step of the true value.
    const double step = M_PI / 2 / 1024;
    for (double x = -7; x < 7; x += 0.01) EXPECT_NEAR(TableCos(x), std::cos(x), step / 2 + 1e-12);
    EXPECT_EQ(TableCos(0), 1.0);
    EXPECT_EQ(TableCos(step * 0.49), 1.0);
}

TEST(Solar, NoonSunAtTheEquinoxStandsAtColatitude) {
    // At solar noon on the equinox (declination about 0) the altitude is 90 deg - latitude.
    Site site{40 * M_PI / 180, 0, 0};
    const int jd = DayOfYear(3, 21);
    EXPECT_NEAR(SolarDeclination(jd), 0, 0.01);
    EXPECT_NEAR(SolarAltitude(site, 0, 12.0), 50 * M_PI / 180, 1e-12);
    EXPECT_NEAR(SolarAzimuth(site, 0, 12.0), 0, 1e-12);  // due south
    EXPECT_GT(SolarAzimuth(site, 0, 15.0), 0);           // west positive in the afternoon
    EXPECT_NEAR(SolarTimeOffset(jd, Site{0, 10 * M_PI / 180, 0}),
                -40.0 / 60 + SolarTimeOffset(jd, site), 1e-12);
}

}  // namespace
}  // namespace dayflux
