#include "sky/perez.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dayflux {
namespace {

constexpr double kEfficacy = 179;

// Sky patches are normalised so that their horizontal illuminance (with RADIANCE's table sine)
// equals the diffuse horizontal illuminance of the Perez efficacy model.
TEST(PerezSky, PatchesReproduceTheDiffuseHorizontalIlluminance) {
    for (int mf : {1, 2, 4}) {
        SkyOptions o;
        o.mf = mf;
        o.sky_color[0] = o.sky_color[1] = o.sky_color[2] = 1;
        o.solar_radiance =
            true;  // -O1: diffuse illuminance = 179 x diffuse irradiance, known exactly
        SkyModel m(o);
        for (double alt_deg : {5.0, 30.0, 60.0, 88.0}) {
            const double alt = alt_deg * M_PI / 180, dif = 150;
            SkyStep s = m.Prepare(600, dif, WeatherUnits::kRadiometric, alt, 1.0, 172, true);
            double e = 0;
            for (int p = 1; p < m.Patches().Size(); ++p) {
                float rgb[3];
                m.SkyValue(s, p, rgb);
                e += rgb[1] * TableSin(m.Patches().Altitude(p)) * m.Patches().SolidAngle(p);
            }
            EXPECT_NEAR(e * kEfficacy, dif * kEfficacy, dif * kEfficacy * 1e-5)
                << "MF " << mf << " alt " << alt_deg;
            // Ground: (diffuse + direct on the horizontal) / pi x reflectance 0.2.
            const double ground = (dif + 600 * std::sin(alt)) * kEfficacy / M_PI / kEfficacy * 0.2;
            EXPECT_NEAR(s.ground[0], ground, ground * 1e-6);
        }
    }
}

// The sun's direct illuminance is spread over the nearest patches without loss.
TEST(PerezSky, SunSpreadConservesDirectIlluminance) {
    for (bool five_phase : {false, true}) {
        SkyOptions o;
        o.mf = 6;
        if (five_phase) {
            o.sun_patches = 1;
            const double r = M_PI / 360 * 0.533;
            o.fixed_sun_solid_angle = r * r * M_PI;
        }
        SkyModel m(o);
        SkyStep s = m.Prepare(700, 80, WeatherUnits::kRadiometric, 0.7, 2.2, 100, true);
        ASSERT_EQ(s.sun.size(), five_phase ? 1u : 4u);
        double e = 0;
        for (const SunPatch &sp : s.sun) {
            const double omega =
                five_phase ? o.fixed_sun_solid_angle : m.Patches().SolidAngle(sp.patch);
            e += sp.value * omega * kEfficacy;
        }
        EXPECT_NEAR(e, s.dir_illum, s.dir_illum * 1e-6);
        // The patches are the nearest ones: the first holds the sun direction.
        double v[3] = {std::cos(0.7) * std::sin(2.2), std::cos(0.7) * std::cos(2.2), std::sin(0.7)};
        EXPECT_EQ(s.sun[five_phase ? 0 : 3].patch, m.Patches().Bin(v[0], v[1], v[2]));
    }
}

TEST(PerezSky, BlackSkyColourLeavesOnlyGroundAndSun) {
    SkyOptions o;
    for (int k = 0; k < 3; ++k) o.sky_color[k] = 0;
    SkyModel m(o);
    SkyStep s = m.Prepare(500, 100, WeatherUnits::kRadiometric, 0.5, 0.3, 80, true);
    EXPECT_FALSE(s.sky_in_use);
    float rgb[3];
    m.SkyValue(s, 5, rgb);
    EXPECT_EQ(rgb[0], 0.f);
    EXPECT_GT(s.ground[0], 0.f);
    EXPECT_EQ(s.sun.size(), 4u);
}

}  // namespace
}  // namespace dayflux
