// DAYSIM's sky division: known patches, the calcomp form the engines evaluate, the centres.
#include "daysim/patches.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <random>

#include "cal/calcomp.h"

namespace dayflux {
namespace {

void FromAltitudeAzimuth(double altitude_deg, double azimuth_deg, double v[3]) {
    const double alt = altitude_deg * M_PI / 180, az = azimuth_deg * M_PI / 180;
    v[0] = std::cos(az) * std::cos(alt);
    v[1] = std::sin(az) * std::cos(alt);
    v[2] = std::sin(alt);
}

int PatchAt(double altitude_deg, double azimuth_deg) {
    double v[3];
    FromAltitudeAzimuth(altitude_deg, azimuth_deg, v);
    return DaysimPatch(v[0], v[1], v[2]);
}

TEST(DaysimPatches, StartEastGoCounterClockwiseGroundLast) {
    EXPECT_EQ(PatchAt(5, 1), 0);       // just north of east
    EXPECT_EQ(PatchAt(5, -1), 29);     // just south of east: the row's last patch
    EXPECT_EQ(PatchAt(5, 90), 7);      // north: 30 x 1/4 = 7.5
    EXPECT_EQ(PatchAt(5, 180), 15);    // west
    EXPECT_EQ(PatchAt(13, 1), 30);     // second row
    EXPECT_EQ(PatchAt(25, 1), 60);     // third row (24 patches)
    EXPECT_EQ(PatchAt(80, 359), 143);  // the last of the six in the top row
    EXPECT_EQ(PatchAt(85, 10), 144);   // zenith cap
    EXPECT_EQ(DaysimPatch(0, 0, 1), 144);
    EXPECT_EQ(PatchAt(-5, 0), 145);        // ground 0-10 degrees below
    EXPECT_EQ(PatchAt(-20, 0), 146);       // 10-30
    EXPECT_EQ(PatchAt(-60, 0), 147);       // below 30
    EXPECT_EQ(DaysimPatch(1, 0, 0), 145);  // the horizon is ground
}

TEST(DaysimPatches, CalcompFormMatchesNative) {
    cal::Context cx;
    cx.LoadRayInit();
    cx.Load(kDaysimPatchCal, FileLoc{"kDaysimPatchCal", 0});
    cal::Expression bin = cx.Compile("dspatch", FileLoc{"-b", 0});
    cal::ChannelArray ray(std::vector<double>(27, 0.0));
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g;
    for (int i = 0; i < 50000; ++i) {
        double d[3] = {g(rng), g(rng), g(rng)};
        const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double &c : d) c /= r;
        std::copy(d, d + 3, ray.values().begin());
        ASSERT_EQ(bin.Evaluate(cx, &ray), DaysimPatch(d[0], d[1], d[2]))
            << d[0] << " " << d[1] << " " << d[2];
    }
    // Edges: along +X (a turn of 0), the zenith, straight down.
    for (const auto &d : std::vector<std::array<double, 3>>{
             {0.9, 0, 0.43589}, {0, 0, 1}, {0, 0, -1}, {-0.9, 0, 0.43589}}) {
        std::copy(d.begin(), d.end(), ray.values().begin());
        EXPECT_EQ(bin.Evaluate(cx, &ray), DaysimPatch(d[0], d[1], d[2]));
    }
}

// lib/daysim.cal (for rcontrib users) holds the same definitions the engines evaluate.
TEST(DaysimPatches, LibraryFileHasTheEnginesDefinitions) {
    std::ifstream in(std::string(DAYFLUX_LIB_DIR) + "/daysim.cal");
    std::stringstream text;
    text << in.rdbuf();
    const std::string file = text.str();
    ASSERT_NE(file.find("Ndsbins : 148;"), std::string::npos);
    EXPECT_EQ(file.substr(file.size() - std::string(kDaysimPatchCal).size()), kDaysimPatchCal);
}

TEST(DaysimPatches, EveryDirectionLandsInItsPatch) {
    for (int p = 0; p < kDaysimDiffusePatches; ++p) {
        double v[3];
        DaysimPatchDirection(p, v);
        EXPECT_NEAR(v[0] * v[0] + v[1] * v[1] + v[2] * v[2], 1, 2e-3) << p;
        EXPECT_EQ(DaysimPatch(v[0], v[1], v[2]), p);
    }
    double v[3];
    DaysimPatchDirection(0, v);  // first row, 6 degrees up, 6 degrees north of east
    EXPECT_NEAR(std::asin(v[2]) * 180 / M_PI, 6, 1e-5);  // in float, as ds_illum keeps it
    EXPECT_NEAR(std::atan2(v[1], v[0]) * 180 / M_PI, 6, 1e-5);
}

}  // namespace
}  // namespace dayflux
