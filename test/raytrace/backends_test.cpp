// The estimator's analytic cases, each scene written once and run on every backend: Embree, and
// Vulkan on the device DAYFLUX_VULKAN_DEVICE names (lavapipe by default; skipped where there is
// none). Both run the same core, so the same exact answers hold within the same errors. The runs
// bin with reinhart.cal at MF:1 (Tregenza's patches, the ground as bin 0), so that on lavapipe
// they share compiled shaders with the other Vulkan tests.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <sstream>

#include "raytrace/core/sampling.h"
#include "raytrace/runs.h"
#include "raytrace/scenes.h"
#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;
namespace {

const std::string kBins = " -e MF:1 -f reinhart.cal -b rbin -bn Nrbins ";

// Tregenza's patch of a direction (reinhart.cal's rbin at MF:1).
int TregenzaBin(double x, double y, double z) {
    const double alt = std::asin(z) * 180 / M_PI;
    double azi = std::atan2(x, y) * 180 / M_PI;
    if (azi < 0) azi += 360;
    static const int first[] = {1, 31, 61, 85, 109, 127, 139},
                     step[] = {12, 12, 15, 15, 20, 30, 60};
    const int row = static_cast<int>(alt / 12);
    if (row >= 7) return 145;
    int col = static_cast<int>((azi + step[row] / 2.0) / step[row]);
    if (azi > 359.9999 - step[row] / 2.0) col = 0;
    return first[row] + col;
}

// Four black walls (modifier `black`) 18 m apart from z = -1 to 2 around the antimatter scenes.
const char kBlackWalls[] =
    "black polygon w1 0 0 12 -9 -9 -1 9 -9 -1 9 -9 2 -9 -9 2\n"
    "black polygon w2 0 0 12 -9 9 -1 -9 9 2 9 9 2 9 9 -1\n"
    "black polygon w3 0 0 12 -9 -9 -1 -9 -9 2 -9 9 2 -9 9 -1\n"
    "black polygon w4 0 0 12 9 -9 -1 9 9 -1 9 9 2 9 -9 2\n";

class Backends : public testing::TestWithParam<const char *> {
  protected:
    void SetUp() override {
        program_ = std::string("rcontrib-gpu -backend ") + GetParam();
        if (!Gpu()) return;
        program_ = "DAYFLUX_VULKAN_DEVICE=${DAYFLUX_VULKAN_DEVICE:-llvmpipe} " + program_;
        WriteFile(tmp_.path() / "sky.rad", kSky);
        const CommandResult r =
            RunCommand("echo '0 0 0 0 0 1' | " + program_ + " -h -I+ -ab 1 -ad 16" + kBins +
                           "-m skyglow sky.rad",
                       tmp_.path());
        ASSERT_EQ(r.status, 0) << r.err;
        if (r.err.find("using Embree") != std::string::npos) GTEST_SKIP() << r.err;
    }
    bool Gpu() const { return std::string(GetParam()) == "vulkan"; }
    // The mean of `count` upward sensors at the origin and its standard error.
    MeanAndError UpwardSensor(const std::string &args, int count) {
        return UpwardSensorMean(tmp_.path(), program_, args, count);
    }
    std::string program_;
    TempDir tmp_;
};

INSTANTIATE_TEST_SUITE_P(, Backends, testing::Values("embree", "vulkan"),
                         [](const testing::TestParamInfo<const char *> &info) {
                             return std::string(info.param) == "embree" ? "Embree" : "Vulkan";
                         });

// A horizontal sensor under a uniform sky of radiance 1: irradiance pi, and each Tregenza bin
// its cosine-weighted solid angle, within the sampling error of n x n stratified samples: a cell
// wholly inside a bin always lands there, a cell across a boundary lands in one of its bins at
// random (variance at most 1/4 a cell), so the tolerance is 5 sqrt(cells across / 4) pi / n^2.
// -asub 2 at -ad 1024 samples the same 64 x 64 cells (32 x 32, each split in 2 x 2).
TEST_P(Backends, UniformSkyGivesPiAndExactBins) {
    WriteFile(tmp_.path() / "sky.rad", kSky);
    // -ad 4096 -lw 1e-6: n = 64 for a sensor (0.8 pi / (4096 1e-6) caps nothing).
    for (const char *sampling : {"-ad 4096", "-ad 1024 -asub 2"}) {
        SCOPED_TRACE(sampling);
        const CommandResult r =
            RunCommand("echo '0 0 0 0 0 1' | " + program_ + " -h -I+ -ab 1 " + sampling +
                           " -lw 1e-6" + kBins + "-m skyglow sky.rad",
                       tmp_.path());
        ASSERT_EQ(r.status, 0) << r.err;
        const std::vector<double> v = NumbersIn(r.out);
        ASSERT_EQ(v.size(), 146u * 3);
        double total = 0;
        for (size_t b = 0; b < 146; ++b) {
            total += v[3 * b];
            EXPECT_EQ(v[3 * b], v[3 * b + 1]);
            EXPECT_EQ(v[3 * b], v[3 * b + 2]);
        }
        // every sample reaches the sky; the GPU's coefficients are floats
        EXPECT_NEAR(total, M_PI, Gpu() ? 1e-5 : 146 * 5e-7 * 0.01 + 1e-6);
        const int n = 64;
        std::vector<int> across(146, 0);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                std::set<int> bins;
                for (int a = 0; a <= 6; ++a)
                    for (int b = 0; b <= 6; ++b) {
                        const core::real2 xy =
                            core::SquareToDisk((j + a / 6.0) / n, (i + b / 6.0) / n);
                        const double z = std::sqrt(std::max(0.0, 1 - dot(xy, xy)));
                        // Any orientation of the tangent plane crosses the same number of cells on
                        // average; this is (y, -x) about +z.
                        bins.insert(TregenzaBin(xy.y, -xy.x, z));
                    }
                if (bins.size() > 1)
                    for (int b : bins) ++across[b];
            }
        const double cell = M_PI / (n * n);
        for (int b = 1; b < 146; ++b) {
            const int row = b == 145 ? 7
                                     : (b < 31    ? 0
                                        : b < 61  ? 1
                                        : b < 85  ? 2
                                        : b < 109 ? 3
                                        : b < 127 ? 4
                                        : b < 139 ? 5
                                                  : 6);
            static const int per_row[] = {30, 30, 24, 24, 18, 12, 6};
            const double a1 = row * 12 * M_PI / 180, a2 = (row + 1) * 12 * M_PI / 180;
            const double exact =
                row == 7
                    ? M_PI * std::pow(std::cos(84 * M_PI / 180), 2)
                    : M_PI / per_row[row] * (std::pow(std::sin(a2), 2) - std::pow(std::sin(a1), 2));
            EXPECT_NEAR(v[3 * b], exact, 5 * std::sqrt(across[b] / 4.0) * cell + 2e-6 * exact)
                << "bin " << b;
        }
        EXPECT_EQ(v[0], 0);  // nothing below the horizon
    }
}

// A sensor inside a closed box of reflectance rho with the walls tracked: every ray hits a wall,
// so the coefficient is pi (1 + rho + ... + rho^(ab-1)) exactly without Russian roulette, and
// the same on average with it (within 4 standard errors of the mean of 400 sensors). With -asub
// every sub-sample counts 1/N^2 of its cell's first hit and one carries all of the rest, so the
// series is exact too.
TEST_P(Backends, FurnaceSumsTheSeries) {
    WriteFile(tmp_.path() / "box.rad",
              "void plastic wall 0 0 5 .5 .5 .5 0 0\n" + CubeOfPolygons("wall"));
    const double rho = .5;
    for (const char *sampling : {"", "-asub 2 "}) {
        SCOPED_TRACE(sampling);
        const std::vector<double> exact_runs = RecordTotals(
            tmp_.path(), program_,
            std::string(sampling) + "-I+ -ab 3 -ad 64 -lw 1e-9" + kBins + "-m wall box.rad", 4,
            "0 0 0 0 0 1");
        ASSERT_EQ(exact_runs.size(), 4u);
        for (double t : exact_runs) EXPECT_NEAR(t, M_PI * (1 + rho + rho * rho), 1e-5);
        const auto [mean, se] = UpwardSensor(
            std::string(sampling) + "-I+ -ab 6 -ad 16 -lw 0.05" + kBins + "-m wall box.rad", 400);
        EXPECT_GT(se, 0);  // roulette did act
        EXPECT_NEAR(mean, M_PI * (1 - std::pow(rho, 6)) / (1 - rho), 4 * se);
    }
}

// RADIANCE's analytic surfaces, exact: a sensor at the centre of a bubble (a sphere seen from
// inside) of reflectance .5 sums the series; a black sphere of radius R at height h hides
// pi R^2 / h^2 of a uniform sky; a glow disc (ring) and a black tube's open end give their view
// factors.
TEST_P(Backends, AnalyticSurfaces) {
    WriteFile(tmp_.path() / "bubble.rad",
              "void plastic wall 0 0 5 .5 .5 .5 0 0\nwall bubble b 0 0 4 0 0 0 3\n");
    const std::vector<double> exact =
        RecordTotals(tmp_.path(), program_,
                     "-I+ -ab 3 -ad 64 -lw 1e-9" + kBins + "-m wall bubble.rad", 2, "0 0 0 0 0 1");
    ASSERT_EQ(exact.size(), 2u);
    for (double t : exact) EXPECT_NEAR(t, M_PI * 1.75, 1e-5);

    const double R = .5, h = 2, L = 3;
    WriteFile(
        tmp_.path() / "sphere.rad",
        std::string(kSky) + "void plastic black 0 0 5 0 0 0 0 0\nblack sphere s 0 0 4 0 0 2 .5\n");
    WriteFile(tmp_.path() / "disc.rad",
              "void glow lamp 0 0 4 1 1 1 0\nlamp ring d 0 0 8 0 0 2 0 0 -1 0 .5\n");
    WriteFile(tmp_.path() / "tube.rad",
              std::string(kSky) +
                  "void plastic black 0 0 5 0 0 0 0 0\nblack tube t 0 0 7 0 0 0 0 0 3 .5\n");
    struct Case {
        const char *args;
        double exact;
    } cases[] = {{"-m skyglow sphere.rad", M_PI * (1 - R * R / (h * h))},
                 {"-m lamp disc.rad", M_PI * R * R / (R * R + h * h)},
                 {"-m skyglow tube.rad", M_PI * R * R / (R * R + L * L)}};
    for (const Case &c : cases) {
        const auto [mean, se] = UpwardSensor("-I+ -ab 1 -ad 1024 -lw 1e-6" + kBins + c.args, 200);
        EXPECT_NEAR(mean, c.exact, 4 * se + 1e-6) << c.args;
        EXPECT_LT(se, 0.01 * c.exact) << c.args;
    }
}

// A closed room under a glow sky lets no light in, however large the scene: with a 2 km ground
// plane around it, rays leaving the floor next to a wall must still find the wall (a start
// offset of 1e-6 of the scene's size, 2 mm, let 0.03 % of the sky in at the corners). On the GPU
// by either traversal.
TEST_P(Backends, ClosedRoomInALargeSceneIsDark) {
    WriteFile(tmp_.path() / "box.rad", ClosedRoomInALargeScene());
    std::string rays;
    for (int i = 0; i < 10; ++i)
        rays += std::to_string(.5 + .4 * i) + " " + std::to_string(.5 + .3 * i) + " .8 0 0 1\n";
    WriteFile(tmp_.path() / "rays", rays);
    for (const char *traversal : {"rayquery", "bvh"}) {
        if (!Gpu() && traversal[0] == 'b') break;
        const CommandResult r = RunCommand(
            program_ + (Gpu() ? std::string(" -gpu_traversal ") + traversal : std::string()) +
                " -h -faa -I+ -ab 4 -ad 1024 -lw 1e-5" + kBins + "-m skyglow box.rad < rays",
            tmp_.path());
        ASSERT_EQ(r.status, 0) << r.err;
        std::istringstream ss(r.out);
        size_t n = 0;
        for (double x; ss >> x; ++n) ASSERT_EQ(x, 0) << traversal;
        EXPECT_EQ(n, 10u * 146 * 3) << traversal;
    }
}

// Antimatter cuts a window in a black ceiling under a glow sky: the box it bounds clips the
// ceiling's material for rays inside it, and leaving the box restores it, so a second black
// plane above the box over half the window hides that half: pi times half the window's view
// factor. Black walls close the room (the scene is kept small: a ray leaving the box within
// 1e-6 of the scene's size of entering it misses its exit). RADIANCE 5.4 agrees by hand on a
// room with a hole cut in a wall, -ab 2.
TEST_P(Backends, AntimatterCutsAWindow) {
    const double a = 1.5, b = 1.0, c = 1.2;
    std::ostringstream s;
    s << "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 360\n"
      << "void plastic black 0 0 5 0 0 0 0 0\n"
      << "black polygon ceiling 0 0 12 -9 -9 " << c << " -9 9 " << c << " 9 9 " << c << " 9 -9 "
      << c << "\n"
      << "black polygon upper 0 0 12 0 -9 " << c + .5 << " 0 9 " << c + .5 << " 9 9 " << c + .5
      << " 9 -9 " << c + .5 << "\n"
      << kBlackWalls << "void antimatter hole 2 void black 0 0\n"
      << BoxOfPolygons("hole", "cut", {-a, -b, c - .1}, {a, b, c + .1});
    WriteFile(tmp_.path() / "cut.rad", s.str());
    const double exact = M_PI * ParallelRectangleViewFactor(a, b, c) / 2;
    const auto [mean, se] =
        UpwardSensor("-I+ -ab 1 -ad 1024 -lw 1e-6" + kBins + "-m skyglow cut.rad", 200);
    EXPECT_GT(se, 0);
    EXPECT_NEAR(mean, exact, 4 * se);
    EXPECT_LT(se, 0.01 * exact);
}

// A rough metal ball under a large spherical lamp, seen by a ray grazing its top: the lamp's
// rough reflection is dirnorm()'s Gaussian lobe, which m_normal() widens by the source's size
// only on flat surfaces (faces and rings: SP_FLAT), so on the ball it stays narrow. RADIANCE
// 5.4 (rcontrib -I- -ab 0 -dj 0, no noise): 8.609127; widened, the lobe would give 1.19.
TEST_P(Backends, RoughLobeOnACurvedSurfaceAsRadiance) {
    WriteFile(tmp_.path() / "ball.rad",
              "void light lamp 0 0 3 100 100 100\nlamp sphere bulb 0 0 4 0 0 3 .6\n"
              "void metal rough 0 0 5 .8 .8 .8 .9 .08\nrough sphere ball 0 0 4 0 0 1 1\n");
    const CommandResult r = RunCommand("echo '0 -3 2 0 1 -0.05' | " + program_ +
                                           " -h -I- -ab 0 -dj 0" + kBins + "-m lamp ball.rad",
                                       tmp_.path());
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream ss(r.out);
    double total = 0;
    int k = 0;
    for (double x; ss >> x; ++k)
        if (k % 3 == 0) total += x;
    EXPECT_NEAR(total, 8.609127, (Gpu() ? 1e-4 : 1e-6) * 8.609127);
}

// A frosted sheet (trans, roughness .2, no diffuse reflection) between an upward sensor and a
// uniform sky of radiance 1: whatever the sheet transmits reaches the sky, so the sensor sees pi
// in each of m_normal()'s three ways: specular transmission sampled about the ray's direction
// (.8) beside the hemisphere behind (.2); all of it specular (the samples alone); and specular
// transmission of .01, below -st (.02), folded into the hemisphere behind (.99 + .01, not .99). No
// variance: every path ends in the sky with its whole coefficient (-lw 1e-6 cuts none).
TEST_P(Backends, RoughTransmissionUnderAUniformSkyGivesPi) {
    WriteFile(tmp_.path() / "sky.rad", kSky);
    for (const char *tspec : {".8", "1", ".01"}) {
        SCOPED_TRACE(tspec);
        WriteFile(tmp_.path() / "sheet.rad",
                  std::string("void trans frost 0 0 7 1 1 1 0 .2 1 ") + tspec +
                      "\nfrost polygon sheet 0 0 12 -50 -50 1 50 -50 1 50 50 1 -50 50 1\n");
        const auto [mean, se] =
            UpwardSensor("-I+ -ab 2 -ad 256 -lw 1e-6" + kBins + "-m skyglow sky.rad sheet.rad", 10);
        EXPECT_NEAR(mean, M_PI, 2e-5 * M_PI);
    }
}

// Antimatter with a material for its inside (m_clip()'s first modifier): a hole cut through a
// black slab 0.5 m thick shows the mirror `pipe` (reflectance 1) where a ray that went through
// the slab's face meets the cut's sides. Every ray from the sensor below that enters the hole
// then reaches the sky, reflected or not: pi times the view factor of the hole's lower opening.
// With void first the sides show the black slab behind them: the upper opening's view factor.
// The reflected rays keep the slab clipped (rayorigin() gives reflections the clip set from
// before m_clip()), or they would stop at the slab's top face. RADIANCE 5.4 gives the void
// answer for both, its m_clip() never finding a penetration (docs/compat.md); its corrected
// m_clip() (rev. 2.14, 2024) counts them as we do.
TEST_P(Backends, AntimatterShadesTheInsideOfItsCut) {
    const double a = 1.5, b = 1.0, c = 1.2, h = .5;
    std::ostringstream s;
    s << "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 360\n"
      << "void plastic black 0 0 5 0 0 0 0 0\nvoid mirror pipe 0 0 3 1 1 1\n"
      << BoxOfPolygons("black", "slab", {-9, -9, c}, {9, 9, c + h}) << kBlackWalls;
    const std::string cut = BoxOfPolygons("hole", "cut", {-a, -b, c - .1}, {a, b, c + h + .1});
    WriteFile(tmp_.path() / "mirror.rad",
              s.str() + "void antimatter hole 2 pipe black 0 0\n" + cut);
    WriteFile(tmp_.path() / "void.rad", s.str() + "void antimatter hole 2 void black 0 0\n" + cut);
    for (const char *file : {"mirror.rad", "void.rad"}) {
        const bool mirror = file[0] == 'm';
        const double exact = M_PI * ParallelRectangleViewFactor(a, b, mirror ? c : c + h);
        const auto [mean, se] =
            UpwardSensor("-I+ -ab 1 -ad 1024 -lw 1e-6" + kBins + "-m skyglow " + file, 200);
        EXPECT_GT(se, 0);
        EXPECT_NEAR(mean, exact, 4 * se) << file;
        EXPECT_LT(se, 0.01 * exact);
    }
}

// Issue 41: a bin beyond the int range or NaN reached int() in the shared core (INT_MIN on x86,
// a write before the record: SIGSEGV). Checked as doubles now: each such ray is reported once as
// a bad bin and ignored, and the rest are binned. Three rays straight at the sky: one whose bin
// is 1e10, one whose bin is NaN (inf - inf: calcomp's library functions give 0 for NaN, as
// RADIANCE's do), one in bin 1.
TEST_P(Backends, BinsBeyondTheIntRangeOrNanAreIgnored) {
    WriteFile(tmp_.path() / "sky.rad", kSky);
    const CommandResult r = RunCommand(
        "printf '0 0 0 0 0 1\\n0 0 0 0 .6 .8\\n0 0 0 0 .95 .3\\n' | " + program_ +
            " -h -ab 0 -bn 2 -b 'if(Dz-.9, 1e10, if(Dz-.5, 1e308*Dz*10 - 1e308*Dz*10, 1))' "
            "-m skyglow sky.rad",
        tmp_.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> v = NumbersIn(r.out);
    ASSERT_EQ(v.size(), 3u * 6);
    const std::vector<double> expected = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1};
    EXPECT_EQ(v, expected);
    EXPECT_NE(r.err.find("bad bin number (ignored)"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dayflux::test
