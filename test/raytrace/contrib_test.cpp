// rcontrib-gpu: analytic cases and RADIANCE's converged references for the tutorial room.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include "raytrace/runs.h"
#include "raytrace/scenes.h"
#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;

namespace {

std::vector<double> Values(const std::string &text, bool binary) {
    const size_t body = text.find("\n\n") + 2;
    std::vector<double> v;
    if (binary) {
        v.resize((text.size() - body) / 4);
        for (size_t i = 0; i < v.size(); ++i) {
            float f;
            std::memcpy(&f, text.data() + body + 4 * i, 4);
            v[i] = f;
        }
    } else {
        std::istringstream ss(text.substr(body));
        double x;
        while (ss >> x) v.push_back(x);
    }
    return v;
}

// Runs a command whose output is an ascii matrix without header; its values (none on failure).
std::vector<double> RunForValues(const std::string &command, const fs::path &dir) {
    CommandResult r = RunCommand(command, dir);
    EXPECT_EQ(r.status, 0) << command << "\n" << r.err;
    return r.status == 0 ? Values("\n\n" + r.out, false) : std::vector<double>{};
}

double RelRms(const std::vector<double> &a, const std::vector<double> &b) {
    double num = 0, den = 0;
    for (size_t i = 0; i < a.size(); ++i) num += (a[i] - b[i]) * (a[i] - b[i]), den += b[i] * b[i];
    return std::sqrt(num / den);
}

std::vector<double> RowSums(const std::vector<double> &a, int rows, int cols) {
    std::vector<double> s(rows, 0.0);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) s[r] += a[(static_cast<size_t>(r) * cols + c) * 3];
    return s;
}

}  // namespace

namespace {

// runs.h's helpers for rcontrib-gpu on its default backend.
std::vector<double> RecordTotals(const fs::path &dir, const std::string &args, int count,
                                 const std::string &ray) {
    return test::RecordTotals(dir, "rcontrib-gpu", args, count, ray);
}
MeanAndError UpwardSensorMean(const fs::path &dir, const std::string &args, int count) {
    return test::UpwardSensorMean(dir, "rcontrib-gpu", args, count);
}

// A glowing rectangle of radiance 1, modifier 'pane', half-widths a (x) and b (y), at height c.
std::string GlowingPane(double a, double b, double c) {
    std::ostringstream pane;
    pane << "void glow pane 0 0 4 1 1 1 0\npane polygon w 0 0 12 " << -a << " " << -b << " " << c
         << "  " << -a << " " << b << " " << c << "  " << a << " " << b << " " << c << "  " << a
         << " " << -b << " " << c << "\n";
    return pane.str();
}

// A run without -asub, then one with it (plain_se holds the first's standard error): its mean
// within 4 standard errors of exact, and the second `closer` times closer than the first.
void ExpectExactThenCloser(double mean, double se, double exact, double closer, double *plain_se) {
    EXPECT_GT(se, 0);
    EXPECT_NEAR(mean, exact, 4 * se);
    if (*plain_se == 0)
        *plain_se = se;
    else
        EXPECT_LT(se, *plain_se / closer);
}

// A closed 2 m cube of reflectance .5 around the origin, modifier 'wall'.
void WriteFurnace(const fs::path &file) {
    WriteFile(file, "void plastic wall 0 0 5 .5 .5 .5 0 0\n" + CubeOfPolygons("wall"));
}

// A distant sun of radiance 1 (modifier 'solar', RADIANCE's 0.533 degrees) at altitude alt
// (radians), due north.

}  // namespace

// Hard cases. A sensor lying exactly on the furnace's floor (RADIANCE starts -I rays 1e-4 off the
// surface) still sees only walls: the series is exact. A sun 0.1 degrees above the horizon gives
// a horizontal sensor sin(0.1 deg) x omega, and a vertical one facing it nearly omega.
TEST(RcontribGpu, SensorOnASurfaceAndGrazingSun) {
    TempDir tmp;
    WriteFurnace(tmp.path() / "box.rad");
    const std::vector<double> on_floor =
        RecordTotals(tmp.path(), "-I+ -ab 3 -ad 64 -lw 1e-9 -m wall box.rad", 2, "0 0 -1 0 0 1");
    ASSERT_EQ(on_floor.size(), 2u);
    for (double t : on_floor) EXPECT_NEAR(t, M_PI * 1.75, 1e-5);

    const double alt = 0.1 * M_PI / 180;
    const double omega = 2 * M_PI * (1 - std::cos(0.533 / 2 * M_PI / 180));
    WriteFile(tmp.path() / "low.rad", SunScene(alt));
    std::vector<double> v = RunForValues(
        "printf '0 0 0 0 0 1\\n0 0 0 0 1 0\\n' | rcontrib-gpu -I+ -ab 0 -dj 0 -faa -h -m solar "
        "low.rad",
        tmp.path());
    ASSERT_EQ(v.size(), 6u);
    EXPECT_NEAR(v[0], std::sin(alt) * omega, 1e-6 * v[0]);
    EXPECT_NEAR(v[3], std::cos(alt) * omega, 1e-6 * v[3]);
}

// A slat 1 mm thick (a closed black box) above a sensor under a uniform sky: the sky it sees is
// pi (1 - view factor of the slat's underside); a ray slipping through the slat would add to it.
TEST(RcontribGpu, ThinSlatDoesNotLeak) {
    TempDir tmp;
    const double a = .6, b = .4, c = .3, th = .001;
    std::ostringstream slat;
    slat << kSky << "void plastic black 0 0 5 0 0 0 0 0\n";
    const double z0 = c, z1 = c + th;
    auto face = [&](const char *name, std::initializer_list<double> p) {
        slat << "black polygon " << name << " 0 0 12";
        for (double x : p) slat << ' ' << x;
        slat << '\n';
    };
    face("bottom", {-a, -b, z0, a, -b, z0, a, b, z0, -a, b, z0});
    face("top", {-a, -b, z1, -a, b, z1, a, b, z1, a, -b, z1});
    face("s1", {-a, -b, z0, -a, -b, z1, a, -b, z1, a, -b, z0});
    face("s2", {-a, b, z0, a, b, z0, a, b, z1, -a, b, z1});
    face("s3", {-a, -b, z0, -a, b, z0, -a, b, z1, -a, -b, z1});
    face("s4", {a, -b, z0, a, -b, z1, a, b, z1, a, b, z0});
    WriteFile(tmp.path() / "slat.rad", slat.str());
    const auto [mean, se] =
        UpwardSensorMean(tmp.path(), "-I+ -ab 1 -ad 1024 -lw 1e-6 -m skyglow slat.rad", 200);
    EXPECT_NEAR(mean, M_PI * (1 - ParallelRectangleViewFactor(a, b, c)), 4 * se);
}

// Coplanar overlapping polygons (a ceiling made twice, the copies overlapping by half): a
// sensor sees the same view factor as with one ceiling, and light neither leaks through the
// overlap nor counts twice: every ray that hits either copy is blocked once.
TEST(RcontribGpu, CoplanarOverlappingPolygons) {
    TempDir tmp;
    const double a = .6, b = .4, c = .3;
    std::ostringstream two;
    two << kSky << "void plastic black 0 0 5 0 0 0 0 0\n"
        << "black polygon p1 0 0 12 " << -a << ' ' << -b << ' ' << c << ' ' << a << ' ' << -b << ' '
        << c << ' ' << a << ' ' << b << ' ' << c << ' ' << -a << ' ' << b << ' ' << c << "\n"
        << "black polygon p2 0 0 12 0 " << -b << ' ' << c << ' ' << a << ' ' << -b << ' ' << c
        << ' ' << a << ' ' << b << ' ' << c << " 0 " << b << ' ' << c << "\n";
    WriteFile(tmp.path() / "two.rad", two.str());
    const auto [mean, se] =
        UpwardSensorMean(tmp.path(), "-I+ -ab 1 -ad 1024 -lw 1e-6 -m skyglow two.rad", 200);
    EXPECT_NEAR(mean, M_PI * (1 - ParallelRectangleViewFactor(a, b, c)), 4 * se);
}

// Double accumulation: at -ad 50000 with 5186 bins (Reinhart MF:6) a sensor's 50176 samples of a
// uniform sky add up to pi within 1e-9 (float accumulators would lose about 1e-6 here), and
// every bin is its own share.
TEST(RcontribGpu, DoubleAccumulationAtManySamples) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", kSky);
    CommandResult r = RunCommand(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -h -fad -I+ -ab 1 -ad 50000 -lw 1e-9 -e MF:6 "
        "-f reinhart.cal -b rbin -bn Nrbins -m skyglow sky.rad",
        tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    std::vector<double> v(r.out.size() / sizeof(double));
    std::memcpy(v.data(), r.out.data(), v.size() * sizeof(double));
    ASSERT_EQ(v.size(), 5186u * 3);
    double total = 0;
    int lit = 0;
    for (size_t b = 0; b < 5186; ++b) {
        total += v[3 * b];
        lit += v[3 * b] > 0;
    }
    EXPECT_NEAR(total, M_PI, 1e-9 * M_PI);
    EXPECT_GT(lit, 4900);  // nearly every patch got samples: they are small against 50176
}

// Rough specular floors under a sun and a sky, seen by a sensor tilted toward them, against
// RADIANCE 5.4's rcontrib -u- -dj 0 -ab 2 -ad 20000 -lw 1e-7: a metal (roughness .2, sampled
// Gaussian reflection and the Gaussian lobe in direct sampling) and a plastic whose specularity
// .015 lies below -st .02 (folded into the diffuse part). Tolerances: 5 x the combined sd (ours
// at -ad 4000 over 12 seeds, RADIANCE's about half of that at -ad 20000).
TEST(RcontribGpu, RoughSpecularAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "metal.rad", RoughFloor(true));
    WriteFile(tmp.path() / "plastic.rad", RoughFloor(false));
    const std::string run =
        "echo '0 -1 1 0 0.7 -0.7' | rcontrib-gpu -dj 0 -I+ -ab 2 -ad 4000 -lw 1e-7 -faa -h "
        "-m solar -m skyglow ";
    std::vector<double> v = RunForValues(run + "metal.rad", tmp.path());
    ASSERT_EQ(v.size(), 6u);
    EXPECT_NEAR(v[0], 4.270985e-05, 5 * 1.12 * 5.2e-8);
    EXPECT_NEAR(v[3], 2.052969, 5 * 1.12 * 0.0027);
    v = RunForValues(run + "plastic.rad", tmp.path());
    ASSERT_EQ(v.size(), 6u);
    EXPECT_NEAR(v[0], 2.512900e-05, 5 * 1.12 * 1.6e-8);
    EXPECT_NEAR(v[3], 1.806924, 5 * 1.12 * 0.0035);
}

// Rough specular transmission against RADIANCE 5.4 (rcontrib -u+ -dj 0 -I+ -ab 2 -ad 20000
// -lw 1e-7, the mean of 100 records per sensor): a horizontal frosted sheet (trans, roughness
// .15) between two sensors and a sun and a 40-degree glow patch above it, one sensor upward, one
// tilted toward the sun. Three sheets: transmission sampled about the ray's direction (the patch
// is seen through the sheet where it is, so samples about the normal halve the upward sensor's
// share), with dirnorm()'s transmitted lobe toward the sun (a); below -st (.5 x .03), folded into
// the hemisphere behind with the whole transmission (b); and below -st with no diffuse
// transmission, where m_normal() sends no hemisphere behind at all and only the lobe passes the
// sun: nothing of the patch, exactly (c). Tolerances: 5 x the combined sd (ours at -ad 16000 over
// 20 records, RADIANCE's mean's).
TEST(RcontribGpu, RoughTransmissionAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", SunAndPatch());
    WriteFile(tmp.path() / "a.rad", FrostedSheet('a'));
    WriteFile(tmp.path() / "b.rad", FrostedSheet('b'));
    WriteFile(tmp.path() / "c.rad", FrostedSheet('c'));
    const std::string run =
        "printf '0 0 0 0 0 1\\n0 0 0 0 0.64 0.77\\n' | rcontrib-gpu -dj 0 -I+ -ab 2 -ad 16000 "
        "-lw 1e-7 -faa -h -m solar -m skyglow sky.rad ";
    // per sheet: sun and patch for each sensor (red), RADIANCE's mean and the tolerance
    struct Expected {
        const char *file;
        double value[4], tolerance[4];
    };
    const Expected cases[] = {
        {"a.rad",
         {3.541313e-05, 0.2145403, 4.333932e-05, 0.1074245},
         {3.4e-7, 1.3e-2, 2.6e-7, 8.0e-3}},
        {"b.rad",
         {2.081556e-05, 0.1234323, 1.853216e-05, 0.1079884},
         {1.2e-8, 7.3e-3, 5.1e-8, 5.5e-3}},
        {"c.rad", {8.273485e-07, 0, 1.084707e-06, 0}, {1.0e-8, 0, 7.5e-9, 0}},
    };
    for (const Expected &e : cases) {
        SCOPED_TRACE(e.file);
        const std::vector<double> v = RunForValues(run + e.file, tmp.path());
        ASSERT_EQ(v.size(), 12u);
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(v[3 * k], e.value[k], e.tolerance[k]) << "value " << k;
    }
}

// aBSDF against RADIANCE 5.4 (rcontrib -u+ -dj 0 -ab 2 -ad 4000 -lw 1e-7, the mean of 100-500
// records per ray): a horizontal sheet between a sun and a 40-degree glow patch above and two
// upward sensors (-I+) and three view rays (-I-) below. Clear glass (Klems data with a strong
// peak): the sun reaches the sensors only by shadow rays passing the peak, exactly, and a view
// ray straight through meets the sun, or the patch, with the peak's value (what is left to
// sample lies below -st: none is drawn). A fabric with some openness (a peak and a surround,
// which the sources near the peak's direction are given instead of the peak), and its view rays
// with every specular sample taken (-st 0), which must leave the peak's direction out.
// Each ray 10 times (40 with -st 0), averaged; tolerances 5 x the combined standard error (ours
// over 20-2000 records, RADIANCE's mean's), 1e-6 relative where neither program has any noise.
TEST(RcontribGpu, ApertureBsdfAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", SunAndPatch());
    for (const char *xml : {"clear.xml", "frads_klems_aniso_high.xml"})
        fs::copy_file(DataDir() / "bsdf" / xml, tmp.path() / xml);
    WriteFile(tmp.path() / "clear.rad", ApertureSheet("clear.xml"));
    WriteFile(tmp.path() / "fabric.rad", ApertureSheet("frads_klems_aniso_high.xml"));
    const std::string sensors = "0 0 0 0 0 1\n0 0 0 0 0.64 0.77\n",
                      views =
                          "0 0 0 0 0.6427876 0.7660444\n0 0 0 0 -.5 .866\n"
                          "0 0 0 0.3 0.2 0.93\n";
    // the mean over `copies` copies of each ray of its sun and patch values (red)
    const auto means = [&](const std::string &rays, int n, const std::string &args, int copies) {
        std::string all;
        for (int k = 0; k < copies; ++k) all += rays;
        WriteFile(tmp.path() / "rays", all);
        const std::vector<double> v =
            RunForValues("rcontrib-gpu -dj 0 -ab 2 -ad 4000 -lw 1e-7 -faa -h -m solar -m skyglow " +
                             args + " < rays",
                         tmp.path());
        std::vector<double> m(2 * n, 0.0);
        EXPECT_EQ(v.size(), 6u * n * copies);
        if (v.size() != 6u * n * copies) return m;
        for (int k = 0; k < copies * n; ++k)
            for (int c = 0; c < 2; ++c) m[2 * (k % n) + c] += v[6 * k + 3 * c] / copies;
        return m;
    };
    struct Expected {
        const char *name;
        std::vector<double> value, tolerance;  // per ray: sun, patch; tolerance < 0: relative
    };
    const Expected cases[] = {
        {"clear -I+",
         {4.617125e-05, 0.2837101, 6.027163e-05, 0.1132549},
         {-1e-6, 1.2e-2, -1e-6, 7.1e-3}},
        {"clear -I-", {0.8867872, 0, 0, 0.8940003, 0, 0}, {-1e-6, 0, 0, -1e-6, 0, 0}},
        {"fabric -I+",
         {6.587252e-07, 3.076999e-03, 7.586447e-07, 2.500740e-03},
         {1.7e-9, 1.3e-4, 2.0e-9, 1.1e-4}},
        {"fabric -I-",
         {7.761145e-03, 4.830078e-04, 9.442795e-08, 1.028697e-02, 5.654222e-08, 3.856412e-04},
         {-1e-6, 7e-6, 5e-10, 1.1e-5, 1.7e-9, 2.9e-5}},
        // every specular sample taken (-st 0, 40 copies, RADIANCE's over 2000 records): those
        // along the peak would see the patch a second time
        {"fabric -I- -st 0",
         {7.761145e-03, 5.575182e-04, 9.441455e-08, 1.087364e-02, 5.659053e-08, 2.932173e-04},
         {-1e-6, 2.0e-3, 2.5e-10, 2.9e-3, 9.4e-10, 2.0e-3}},
    };
    for (const Expected &e : cases) {
        SCOPED_TRACE(e.name);
        const std::string name = e.name;
        const bool views_run = name.find("-I-") != std::string::npos;
        const bool sampled = name.find("-st 0") != std::string::npos;
        const std::vector<double> m = means(views_run ? views : sensors, views_run ? 3 : 2,
                                            std::string(sampled ? "-st 0 " : "") +
                                                (views_run ? "-I- sky.rad " : "-I+ sky.rad ") +
                                                (name[0] == 'c' ? "clear.rad" : "fabric.rad"),
                                            sampled ? 40 : 10);
        ASSERT_EQ(m.size(), e.value.size());
        for (size_t k = 0; k < m.size(); ++k) {
            const double tol = e.tolerance[k] < 0 ? -e.tolerance[k] * e.value[k] : e.tolerance[k];
            EXPECT_NEAR(m[k], e.value[k], tol) << "value " << k;
        }
    }
}

// mixfunc against RADIANCE 5.4 (rcontrib -u- -ab 2 -ad 20000 -lw 1e-6): a floor half white, half
// black (by the sign of Px) and a screen above the sensor 30 % black, 70 % void (transparent).
// Tolerance: 5 x the combined sd (ours at -ad 4000 over 10 seeds; RADIANCE's about half). The
// second sensor's line starts with a minus sign, which is data, not a resolution line.
TEST(RcontribGpu, MixfuncAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "mix.cal", kMixCal);
    WriteFile(tmp.path() / "mix.rad", MixfuncHalvesAndScreen());
    const std::vector<double> v = RunForValues(
        "printf '0 0 .5 0 0 1\\n-3 3 1 0 0 -1\\n' | rcontrib-gpu -I+ -ab 2 -ad 4000 -lw 1e-6 "
        "-faa -h -m skyglow mix.rad",
        tmp.path());
    ASSERT_EQ(v.size(), 6u);
    EXPECT_NEAR(v[0], 2.804347, 5 * 1.12 * 0.0010);
    EXPECT_NEAR(v[3], 1.259178, 5 * 1.12 * 0.0025);
}

// -se: the standard errors it reports match the spread of independent records. With 200
// records the observed sd is known to ~5 % and the rms of the reported errors to a few %, so
// their ratio must lie within 0.8-1.25.
TEST(RcontribGpu, StandardErrorsMatchTheSpread) {
    TempDir tmp;
    WriteFurnace(tmp.path() / "box.rad");
    const std::vector<double> results = RecordTotals(
        tmp.path(), "-se se.txt -I+ -ab 3 -ad 64 -lw 0.05 -m wall box.rad", 200, "0 0 0 0 0 1");
    ASSERT_EQ(results.size(), 200u);
    const std::vector<double> se = Values(
        "\n\n" +
            [&] {
                const std::string t = ReadFile(tmp.path() / "se.txt");
                return t.substr(t.find("\n\n") + 2);
            }(),
        false);
    ASSERT_EQ(se.size(), 200u * 3);
    double mean, sem, ms = 0;
    MeanAndStandardError(results, &mean, &sem);
    const double sd = sem * std::sqrt(200.0);
    for (size_t i = 0; i < se.size(); i += 3) ms += se[i] * se[i];
    const double rms = std::sqrt(ms / 200);
    EXPECT_GT(sd / rms, 0.8) << sd << " " << rms;
    EXPECT_LT(sd / rms, 1.25) << sd << " " << rms;
    EXPECT_NEAR(mean, M_PI * 1.75, 4 * sem);  // and the replicas' mean is unbiased
}

// A sensor under a rectangular glow window parallel to it: pi times the view factor.
TEST(RcontribGpu, ViewFactorOfAWindow) {
    TempDir tmp;
    const double a = 1.5, b = 1.0, c = 1.2;  // half-widths and height
    WriteFile(tmp.path() / "win.rad", GlowingPane(a, b, c));
    // Corner view factor of a parallel rectangle (x by y at distance c), four times.
    const double exact = M_PI * ParallelRectangleViewFactor(a, b, c);
    double plain_se = 0;
    for (const char *sampling : {"", "-asub 3 "}) {
        SCOPED_TRACE(sampling);
        const auto [mean, se] = UpwardSensorMean(
            tmp.path(), std::string(sampling) + "-I+ -ab 1 -ad 1024 -lw 1e-6 -m pane win.rad", 200);
        EXPECT_LT(se, 0.01 * exact);  // and the estimate is a good one
        // 3 x 3 sub-samples: the cells across the window's edge are 3 times as many and each a
        // ninth the size, so the error falls about 3^1.5 = 5.2 times (5.6 measured); nine
        // samples jittered over the whole cell would give 3. (Standard errors of 200 runs are
        // good to about 5 %.)
        ExpectExactThenCloser(mean, se, exact, 4.5, &plain_se);
    }
}

// -asub splits only the cells near what a specular path could start from, found by a probe along
// each cell's centre (hemisphere.inl): a glowing strip a third of a cell wide, which many probes
// miss, is still seen in the right amount, by the cells left whole (their one ray carries the
// whole cell) as by the cells split. With a whole cell's coefficient divided by N^2, or its ray
// not the chosen sub-sample (so not uniform over the cell), the mean is off (both tried).
TEST(RcontribGpu, SubsamplesOnlyNearTargetsWithoutBias) {
    TempDir tmp;
    const double a = 1.5, b = 0.015, c = 1.2;  // at -ad 1024, cells about 3.5 degrees wide
    WriteFile(tmp.path() / "strip.rad", GlowingPane(a, b, c));
    const double exact = M_PI * ParallelRectangleViewFactor(a, b, c);
    const auto [mean, se] =
        UpwardSensorMean(tmp.path(), "-asub 3 -I+ -ab 1 -ad 1024 -lw 1e-6 -m pane strip.rad", 400);
    EXPECT_GT(se, 0);
    EXPECT_NEAR(mean, exact, 4 * se);
    EXPECT_LT(se, 0.05 * exact);
}

// -asub's receiver sampling (hemisphere.inl): a sensor 1 m above a wide floor of reflectance .5,
// facing it, under a glowing pane 2 m up, which only the floor's hemispheres reach (one cell
// each at -lw 3e-3, so no collision rule: exact). The floor's radiance is .5 times its view
// factor F to the pane, so the sensor's irradiance is .5 pi times F's mean over the
// cosine-weighted directions it looks along. Both with and without -asub; with it, the floor
// also samples the pane directly and the two shares add to one: the same mean, four times
// closer (3.5 times measured). A hemisphere ray counting its whole coefficient beside the
// samples (no share) gives 1.8 times the answer, the samples left out a fifth (both tried).
TEST(RcontribGpu, SampledReceiversWithoutBias) {
    TempDir tmp;
    const double a = 1.5, b = 1.0, height = 2.0;
    WriteFile(tmp.path() / "pane.rad",
              "void plastic floor 0 0 5 .5 .5 .5 0 0\n"
              "floor polygon f 0 0 12 -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0\n" +
                  GlowingPane(a, b, height));
    // The view factor from floor point (x, y) to the pane: its four corners' rectangles, signed.
    const auto corner = [&](double x, double y) {
        const double sx = x < 0 ? -1 : 1, sy = y < 0 ? -1 : 1;
        return sx * sy * ParallelRectangleViewFactor(std::abs(x), std::abs(y), height) / 4;
    };
    const auto view_factor = [&](double x, double y) {
        return corner(a - x, b - y) - corner(-a - x, b - y) - corner(a - x, -b - y) +
               corner(-a - x, -b - y);
    };
    double sum = 0;  // midpoints in sin^2 of the angle from the nadir and in azimuth
    const int ns = 800, nphi = 128;
    for (int i = 0; i < ns; ++i) {
        const double s = (i + 0.5) / ns, r = std::sqrt(s / (1 - s));  // the floor point's radius
        for (int j = 0; j < nphi; ++j) {
            const double phi = 2 * M_PI * (j + 0.5) / nphi;
            sum += view_factor(r * std::cos(phi), r * std::sin(phi));
        }
    }
    const double exact = 0.5 * M_PI * sum / (ns * nphi);
    double plain_se = 0;
    for (const char *sampling : {"", "-asub 3 "}) {
        SCOPED_TRACE(sampling);
        const std::vector<double> t = RecordTotals(
            tmp.path(), std::string(sampling) + "-I+ -ab 2 -ad 256 -lw 3e-3 -m pane pane.rad", 400,
            "0 0 1 0 0 -1");
        ASSERT_EQ(t.size(), 400u);
        double mean, se;
        test::MeanAndStandardError(t, &mean, &se);
        ExpectExactThenCloser(mean, se, exact, 2.5, &plain_se);
    }
}

// -asub's receiver samples against the hemispheres alone, where the sampling is less symmetric
// than SampledReceiversWithoutBias's: a pane tilted 45 degrees (the cosines at either end
// differ) given as a pentagon (triangles of unequal areas), seen off-centre; the same pane
// twice, back to back (a sample counts only on the object it picked: else the light doubles);
// and -lr -1, which stops the hemispheres' rays and so must stop the samples.
TEST(RcontribGpu, SampledReceiversAsHemispheresAlone) {
    TempDir tmp;
    const std::string floor =
        "void plastic floor 0 0 5 .5 .5 .5 0 0\n"
        "floor polygon f 0 0 12 -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0\n"
        "void glow pane 0 0 4 1 1 1 0\n";
    WriteFile(tmp.path() / "tilted.rad",
              floor + "pane polygon w 0 0 15 -1.5 -1 1  -1.5 1 3  1.5 1 3  1.5 -1 1  -0.9 -1 1\n");
    WriteFile(tmp.path() / "twice.rad",
              floor + "pane polygon w 0 0 12 -1 -1 2  -1 1 2  1 1 2  1 -1 2\n" +
                  "pane polygon v 0 0 12 1 -1 2  1 1 2  -1 1 2  -1 -1 2\n");
    for (const char *scene : {"tilted.rad", "twice.rad"}) {
        SCOPED_TRACE(scene);
        double mean[2], se[2];
        for (int sub = 0; sub < 2; ++sub) {
            const std::vector<double> t = RecordTotals(
                tmp.path(),
                std::string(sub ? "-asub 3 " : "") + "-I+ -ab 2 -ad 256 -lw 3e-3 -m pane " + scene,
                400, "0.7 0.3 1 0 0 -1");
            ASSERT_EQ(t.size(), 400u);
            test::MeanAndStandardError(t, &mean[sub], &se[sub]);
        }
        EXPECT_GT(mean[0], 0.05);
        EXPECT_NEAR(mean[1], mean[0], 4 * std::hypot(se[0], se[1]));
    }
    const std::vector<double> t =
        RecordTotals(tmp.path(), "-asub 3 -lr -1 -I+ -ab 2 -ad 256 -lw 3e-3 -m pane twice.rad", 4,
                     "0 0 1 0 0 -1");
    ASSERT_EQ(t.size(), 4u);
    for (double v : t) EXPECT_EQ(v, 0.0);
}

// The deeper bounces' directions: a sensor 1 m above a wide floor of reflectance .5, facing it,
// under a glowing cap of half-angle 30 degrees about the zenith and nothing else. The floor's
// irradiance is pi sin^2(30) (a cosine-weighted hemisphere puts sin^2 of its samples within the
// cap; uniform directions would put 1 - cos), so the sensor's is pi .5 / 4. At -lw 3e-3 the
// floor's hemispheres have one cell (pushed at once, in a fixed frame): exact. At -lw 1e-7 they
// have two by two, where RADIANCE's collision rule pushes samples away from the zenith its four
// cells share: RADIANCE 5.4's rcontrib gives 0.36486 (standard error 0.00043 over 2000 runs),
// 7 % low, and so must we.
TEST(RcontribGpu, DeeperBouncesAreCosineWeighted) {
    TempDir tmp;
    WriteFile(tmp.path() / "cap.rad",
              "void plastic floor 0 0 5 .5 .5 .5 0 0\n"
              "floor polygon f 0 0 12 -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0\n"
              "void glow capglow 0 0 4 1 1 1 0\ncapglow source cap 0 0 4 0 0 1 60\n");
    const double exact = M_PI * 0.5 * 0.25, radiance = 0.36486, radiance_se = 0.00043;
    for (const char *lw : {"-lw 3e-3", "-lw 1e-7"}) {
        SCOPED_TRACE(lw);
        const std::vector<double> t =
            RecordTotals(tmp.path(), std::string("-I+ -ab 2 -ad 256 ") + lw + " -m capglow cap.rad",
                         400, "0 0 1 0 0 -1");
        ASSERT_EQ(t.size(), 400u);
        double mean, se;
        test::MeanAndStandardError(t, &mean, &se);
        EXPECT_LT(se, 0.01 * exact);
        if (std::string(lw) == "-lw 3e-3") {
            EXPECT_NEAR(mean, exact, 4 * se);
        } else {
            EXPECT_NEAR(mean, radiance, 4 * std::hypot(se, radiance_se));
            EXPECT_LT(mean, exact - 10 * se);
        }
    }
}

// The tutorial room against RADIANCE's converged runs. RADIANCE's own runs at these settings
// differ from the converged matrix by 0.071-0.073 (DC) and 0.078-0.079 (V) per entry, 1-2 % on
// row sums, and by up to 0.9 % (DC) and 0.5 % (V) in total (shared/data/references/README.md).
class RoomAgainstRadiance : public testing::Test {
  protected:
    CommandResult Run(const std::string &args, const std::string &scene) {
        return RunCommand("rcontrib-gpu -I+ -ab 4 -ad 8192 -lw 1e-4 -faf " + args + " " + scene +
                              " < '" + (DataDir() / "rcontrib/points.txt").string() + "'",
                          DataDir() / "scene/models/room");
    }
    void Expect(const CommandResult &r, const char *ref, int cols, double entry_tol,
                double total_tol) {
        ASSERT_EQ(r.status, 0) << r.err;
        std::vector<double> ours = Values(r.out, true),
                            conv = Values(ReadFile(DataDir() / "rcontrib" / ref), true);
        ASSERT_EQ(ours.size(), conv.size());
        EXPECT_LT(RelRms(ours, conv), entry_tol);
        EXPECT_LT(RelRms(RowSums(ours, 100, cols), RowSums(conv, 100, cols)), 0.03);
        double so = 0, sc = 0;
        for (size_t i = 0; i < ours.size(); ++i) so += ours[i], sc += conv[i];
        EXPECT_NEAR(so / sc, 1.0, total_tol);
    }
};

TEST_F(RoomAgainstRadiance, DaylightCoefficients) {
    Expect(Run("-e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow",
               "materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"),
           "dc_conv.fmx", 292, 0.09, 0.015);
}

// -asub 2 at a quarter of the samples: the same answer within the same tolerance.
TEST_F(RoomAgainstRadiance, DaylightCoefficientsSubsampled) {
    const std::string scene = "materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad";
    Expect(RunCommand("rcontrib-gpu -asub 2 -I+ -ab 4 -ad 2048 -lw 1e-4 -faf -e MF:1 -f "
                      "reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow " +
                          scene + " < '" + (DataDir() / "rcontrib/points.txt").string() + "'",
                      DataDir() / "scene/models/room"),
           "dc_conv.fmx", 292, 0.09, 0.015);
}

TEST_F(RoomAgainstRadiance, ViewMatrix) {
    Expect(Run("-f klems_full.cal -b 'kbin(0,1,0,0,0,1)' -bn Nkbins -m Glazing",
               "materials.rad room.rad objects/GlazingVmtx.rad"),
           "v_conv.fmx", 145, 0.10, 0.015);
}

// -asub 3 at a quarter of the samples, the room's surfaces sampling the window directly: closer
// than RADIANCE's own runs at -ad 8192 (0.049 per entry measured; without the window's samples,
// 0.09 and more, which -lw's cut-off paths leave whatever -ad gives).
TEST_F(RoomAgainstRadiance, ViewMatrixReceiversSampled) {
    Expect(RunCommand("rcontrib-gpu -asub 3 -I+ -ab 4 -ad 2048 -lw 1e-4 -faf -f klems_full.cal -b "
                      "'kbin(0,1,0,0,0,1)' -bn Nkbins -m Glazing materials.rad room.rad "
                      "objects/GlazingVmtx.rad < '" +
                          (DataDir() / "rcontrib/points.txt").string() + "'",
                      DataDir() / "scene/models/room"),
           "v_conv.fmx", 145, 0.06, 0.015);
}

// Direct sun coefficients C_ds: one deterministic shadow ray per sun (-dj 0), so RADIANCE's own
// matrix is matched to float rounding; a ray grazing a window edge may go either way.
TEST(RcontribGpu, SunCoefficientsMatchRadiance) {
    const fs::path oct = DataDir() / "rcontrib/cds.oct";
    CommandResult r = RunCommand(
        "rcontrib-gpu -I+ -ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal "
        "-b rbin -bn Nrbins -m solar '" +
            oct.string() + "' < '" + (DataDir() / "rcontrib/points.txt").string() + "'",
        DataDir());
    ASSERT_EQ(r.status, 0) << r.err;
    CommandResult ref =
        RunCommand("xzcat '" + (DataDir() / "matrix/cds_test.fmx.xz").string() + "'", DataDir());
    ASSERT_EQ(ref.status, 0);
    const std::vector<double> ours = Values(r.out, true), theirs = Values(ref.out, true);
    ASSERT_EQ(ours.size(), theirs.size());
    ASSERT_EQ(ours.size(), 100u * 5186 * 3);
    size_t lit = 0, differ = 0;
    for (size_t i = 0; i < ours.size(); ++i) {
        lit += theirs[i] > 0;
        if (std::fabs(ours[i] - theirs[i]) > 1e-6 * std::fabs(theirs[i]) + 1e-30) ++differ;
    }
    EXPECT_GT(lit, 10000u);  // the suns do reach the sensors
    EXPECT_LE(differ, 3u);
}

// -M: a file of modifier names, each tracked as if named by -m, in the file's order; here 2000
// suns of radiance 1, each its own modifier (as direct-sun workflows track them), seen by a
// sensor facing up: column j is the sine of the altitude of the j-th sun named times its
// solid angle. The file lists them in an order of its own. A name given twice is an error.
// Modifiers whose -p parameters are the same share one calcomp context. An output file per
// modifier may mean more open files than the soft limit allows.
TEST(RcontribGpu, ModifierFileOfManySuns) {
    TempDir tmp;
    constexpr int kSuns = 2000;
    const double half = 0.533 / 2 * M_PI / 180, omega = 2 * M_PI * (1 - std::cos(half));
    std::ostringstream suns, names;
    suns.precision(17);
    std::vector<double> altitude(kSuns);
    for (int i = 0; i < kSuns; ++i) {
        altitude[i] = (1 + 88. * i / kSuns) * M_PI / 180;
        const double az = 2 * M_PI * i / 7.3;
        suns << "void light sol" << i << " 0 0 3 1 1 1\nsol" << i << " source s" << i << " 0 0 4 "
             << std::cos(altitude[i]) * std::sin(az) << " " << std::cos(altitude[i]) * std::cos(az)
             << " " << std::sin(altitude[i]) << " 0.533\n";
    }
    std::vector<int> order(kSuns);
    for (int j = 0; j < kSuns; ++j) order[j] = (j * 7 + 3) % kSuns;  // 7 is prime to 2000
    for (int j = 0; j < kSuns; ++j) names << "sol" << order[j] << (j % 10 == 9 ? "\n" : " ");
    WriteFile(tmp.path() / "suns.rad", suns.str());
    WriteFile(tmp.path() / "suns.mod", names.str());
    const std::vector<double> v = RunForValues(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -dj 0 -faa -h -M suns.mod suns.rad",
        tmp.path());
    ASSERT_EQ(v.size(), 3u * kSuns);
    for (int j = 0; j < kSuns; ++j) {
        const double exact = std::sin(altitude[order[j]]) * omega;
        EXPECT_NEAR(v[3 * j], exact, 1e-6 * exact) << j;
    }
    // Modifiers with the same -p share a calcomp context; different -p, different contexts.
    const std::vector<double> p = RunForValues(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -dj 0 -faa -h -bn 3 -b B -p B=2 -m sol0 "
        "-m sol1 -p B=1 -m sol2 suns.rad",
        tmp.path());
    ASSERT_EQ(p.size(), 3u * 9);
    for (int k = 0; k < 3; ++k)
        for (int bin = 0; bin < 3; ++bin) {
            const double exact = std::sin(altitude[k]) * omega;
            EXPECT_NEAR(p[3 * (3 * k + bin)], bin == (k < 2 ? 2 : 1) ? exact : 0, 1e-6 * exact)
                << k << " " << bin;
        }
    // A file per modifier, more of them than the soft limit of open files allows: raised to
    // the hard limit (RADIANCE stops at the soft one).
    std::ostringstream first300;
    for (int i = 0; i < 300; ++i) first300 << "sol" << i << "\n";
    WriteFile(tmp.path() / "first300.mod", first300.str());
    fs::create_directory(tmp.path() / "out");
    struct rlimit files;
    ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &files), 0);
    if (files.rlim_max >= 1024) {
        const CommandResult many = RunCommand(
            "ulimit -Sn 128 && echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -dj 0 -faa "
            "-o out/%s.txt -M first300.mod suns.rad",
            tmp.path());
        ASSERT_EQ(many.status, 0) << many.err;
        for (int i : {0, 150, 299}) {
            const std::vector<double> one =
                Values(ReadFile(tmp.path() / "out" / ("sol" + std::to_string(i) + ".txt")), false);
            ASSERT_EQ(one.size(), 3u) << i;
            EXPECT_NEAR(one[0], std::sin(altitude[i]) * omega, 1e-6 * one[0]) << i;
        }
    }
    WriteFile(tmp.path() / "twice.mod", "sol1 sol2\nsol1\n");
    const CommandResult r =
        RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -M twice.mod suns.rad", tmp.path());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("duplicate modifier 'sol1'"), std::string::npos) << r.err;
}

// One sun of radiance 1 and no geometry: a sensor sees ldot times the sun's solid angle;
// behind a pane of glass, that times the pane's transmittance; behind an opaque one, nothing.
TEST(RcontribGpu, DirectSunIsAnalytic) {
    TempDir tmp;
    const double alt = 40 * M_PI / 180, half = 0.533 / 2 * M_PI / 180;
    WriteFile(tmp.path() / "sun.rad", SunScene(alt));
    const std::string pane = "p polygon pane 0 0 12 -5 -5 1 5 -5 1 5 5 1 -5 5 1\n";
    WriteFile(tmp.path() / "glass.rad", "void glass p 0 0 3 .96 .96 .96\n" + pane);
    WriteFile(tmp.path() / "black.rad", "void plastic p 0 0 5 0 0 0 0 0\n" + pane);
    const std::string run =
        "echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -dj 0 -faa -h -m solar sun.rad ";
    const double omega = 2 * M_PI * (1 - std::cos(half));
    std::vector<double> v = RunForValues(run, tmp.path());
    ASSERT_EQ(v.size(), 3u);
    EXPECT_NEAR(v[0], std::sin(alt) * omega, 1e-6 * v[0]);
    // Glass: RADIANCE's transmittance for transmissivity .96 at incidence 50 degrees, n = 1.52.
    const double ci = std::sin(alt), n = 1.52;
    const double ct = std::sqrt(1 - (1 - ci * ci) / (n * n));
    const double tn = std::pow(.96, 1 / ct);
    const double re = std::pow((ci - n * ct) / (ci + n * ct), 2);
    const double rm = std::pow((1 / ci - n / ct) / (1 / ci + n / ct), 2);
    const double trans = .5 * (1 - re) * (1 - re) * tn / (1 - re * re * tn * tn) +
                         .5 * (1 - rm) * (1 - rm) * tn / (1 - rm * rm * tn * tn);
    v = RunForValues(run + "glass.rad", tmp.path());
    ASSERT_FALSE(v.empty());
    EXPECT_NEAR(v[0], std::sin(alt) * omega * trans, 1e-6 * v[0]);
    v = RunForValues(run + "black.rad", tmp.path());
    ASSERT_FALSE(v.empty());
    EXPECT_EQ(v[0], 0);
    // trans: the shadow ray passes its specular transmission, colour x tspec, where RADIANCE's
    // Fresnel estimate at the pane has raised the specularity and so lowered the transmission.
    WriteFile(tmp.path() / "trans.rad", "void trans p 0 0 7 .6 .7 .8 .04 0 .5 .3\n" + pane);
    v = RunForValues(run + "trans.rad", tmp.path());
    ASSERT_FALSE(v.empty());
    const double rspec = .04 + (std::exp(-5.85 * ci) - 0.00287989916) * (1 - .04);
    const double tspec = .5 * (1 - rspec) * .3;
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(v[k], (.6 + .1 * k) * tspec * ci * omega, 1e-6 * v[k]) << k;
    // rcontrib's default -dj .9 aims anywhere within .9 x 1.13 x .886 = .9 sun radii of the
    // centre along each side of a square, so at most 1.27 radii off: ldot moves by less than
    // cos(alt) x 1.5 angular radii.
    v = RunForValues("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -ab 0 -faa -h -m solar sun.rad",
                     tmp.path());
    ASSERT_FALSE(v.empty());
    EXPECT_NE(v[0], std::sin(alt) * omega);
    EXPECT_NEAR(v[0], std::sin(alt) * omega, std::cos(alt) * 1.5 * half * omega);
}

// The room moved 1000 km from the origin gives the room's numbers: the backend recentres the scene
// before storing it in float. Identical ray trees give identical numbers; one ray that went another
// way would change only a little, while float geometry at 1e6 m (ulp 6 cm) would change the row
// sums by far more than independent seeds do (3.8 % here).
TEST(RcontribGpu, FarFromTheOriginTracesTheSame) {
    TempDir tmp;
    std::ostringstream pts;
    pts.precision(17);
    std::istringstream in(ReadFile(DataDir() / "rcontrib/points.txt"));
    double p[6];
    while (in >> p[0] >> p[1] >> p[2] >> p[3] >> p[4] >> p[5])
        pts << p[0] + 1e6 << ' ' << p[1] + 1e6 << ' ' << p[2] << ' ' << p[3] << ' ' << p[4] << ' '
            << p[5] << '\n';
    WriteFile(tmp.path() / "far.txt", pts.str());
    const fs::path room = DataDir() / "scene/models/room";
    WriteFile(tmp.path() / "far.rad",
              "!xform -t 1e6 1e6 0 materials.rad room.rad "
              "objects/Glazing.rad\n");
    const std::string cmd =
        "rcontrib-gpu -I+ -ab 2 -ad 256 -lw 1e-3 -faf -e MF:1 -f reinhart.cal -b rbin -bn Nrbins "
        "-m skyglow ";
    CommandResult near = RunCommand(cmd +
                                        "materials.rad room.rad objects/Glazing.rad "
                                        "skyDomes/skyglow.rad < '" +
                                        (DataDir() / "rcontrib/points.txt").string() + "'",
                                    room);
    CommandResult far =
        RunCommand(cmd + "'" + (tmp.path() / "far.rad").string() + "' skyDomes/skyglow.rad < '" +
                       (tmp.path() / "far.txt").string() + "'",
                   room);
    ASSERT_EQ(near.status + far.status, 0) << near.err << far.err;
    const std::vector<double> a = Values(near.out, true), b = Values(far.out, true);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_LT(RelRms(RowSums(b, 100, 146), RowSums(a, 100, 146)), 0.005);
    EXPECT_LT(RelRms(b, a), 0.05);
}

// -c as rcontrib's: records average -c rays (a zero-direction ray counts as one that adds
// nothing), a partial final record averages the rays it got, -c 0 sums every ray into one record
// and ignores zero rays. One sun at 40 degrees, -dj 0: each sensor gets exactly cos x omega.
TEST(RcontribGpu, AccumulationAsRcontrib) {
    TempDir tmp;
    const double alt = 40 * M_PI / 180;
    const double omega = 2 * M_PI * (1 - std::cos(0.533 / 2 * M_PI / 180));
    WriteFile(tmp.path() / "sun.rad", SunScene(alt));
    const double normals[7][3] = {{0, 0, 1}, {0, 0, 0}, {0, 1, 0}, {0, .5, 1},
                                  {1, 0, 1}, {0, 1, 1}, {0, 0, 1}};
    std::string rays;
    double e[7];
    for (int i = 0; i < 7; ++i) {
        const double *n = normals[i];
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        e[i] = len == 0 ? 0 : (n[1] * std::cos(alt) + n[2] * std::sin(alt)) / len * omega;
        rays += "0 0 0 " + std::to_string(n[0]) + " " + std::to_string(n[1]) + " " +
                std::to_string(n[2]) + "\n";
    }
    WriteFile(tmp.path() / "rays", rays);
    auto run = [&](const std::string &c) {
        CommandResult r = RunCommand(
            "rcontrib-gpu -c " + c + " -I+ -ab 0 -dj 0 -h -m solar sun.rad < rays", tmp.path());
        EXPECT_EQ(r.status, 0) << r.err;
        std::vector<double> v = Values("\n\n" + r.out, false), first;
        for (size_t i = 0; i < v.size(); i += 3) first.push_back(v[i]);
        return first;
    };
    std::vector<double> v = run("3");
    ASSERT_EQ(v.size(), 3u);
    EXPECT_NEAR(v[0], (e[0] + e[1] + e[2]) / 3, 1e-6 * v[0]);
    EXPECT_NEAR(v[1], (e[3] + e[4] + e[5]) / 3, 1e-6 * v[1]);
    EXPECT_NEAR(v[2], e[6], 1e-6 * v[2]);  // partial: one ray
    // -progress ends with the finished count when the total is known.
    CommandResult r = RunCommand(
        "rcontrib-gpu -progress -y 3 -c 2 -I+ -ab 0 -h -m solar sun.rad < rays", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("3 of 3 records (100.0%)"), std::string::npos) << r.err;
    v = run("0");
    ASSERT_EQ(v.size(), 1u);
    double total = 0;
    for (double x : e) total += x;
    EXPECT_NEAR(v[0], total, 1e-6 * total);
}

// -i: irradiance where a ray first meets an opaque surface, seen through glass: a floor under an
// open sky of radiance 1 gets pi, whatever the floor's material, and a pane between the ray's
// origin and the floor is passed.
TEST(RcontribGpu, FirstHitIrradiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "scene.rad",
              std::string(kSky) +
                  "void plastic dark 0 0 5 .1 .1 .1 0 0\n"
                  "dark polygon floor 0 0 12 -1e3 -1e3 0 1e3 -1e3 0 1e3 1e3 0 -1e3 1e3 0\n"
                  "void glass clear 0 0 3 .9 .9 .9\n"
                  "clear polygon pane 0 0 12 -1 -1 2 1 -1 2 1 1 2 -1 1 2\n");
    std::vector<double> v = RunForValues(
        "echo '0 0 3 0 0 -1' | rcontrib-gpu -i+ -ab 1 -ad 400 -lw 1e-6 -faa -h -m skyglow "
        "scene.rad",
        tmp.path());
    ASSERT_EQ(v.size(), 3u);
    // The floor's hemisphere sees the sky, the pane above cutting it a little. RADIANCE 5.4's
    // rcontrib -i gives 3.0094 at -ad 4000 (sd ~.001); one of our -ad 400 runs has sd .0032
    // (20 seeds), so 5 sd of the difference is .017.
    EXPECT_NEAR(v[0], 3.0094, 0.017);
    v = RunForValues(
        "echo '500 500 3 0 0 -1' | rcontrib-gpu -i+ -ab 1 -ad 400 -lw 1e-6 -faa -h -m skyglow "
        "scene.rad",
        tmp.path());
    ASSERT_FALSE(v.empty());
    EXPECT_NEAR(v[0], M_PI, 1e-6);  // away from the pane: the whole sky
}

// Suns in the furnished room (-ab 1: direct sun plus one bounce off the room and the ground): the
// row sums of the first four sensors against the mean of four RADIANCE 5.4 runs (rcontrib -u+
// -ab 1 -ad 1024 -lw 1e-5, default -dj .9). Tolerance: 5 x the combined sd (ours over 6 seeds:
// 0.2-0.5 %; RADIANCE's mean: its run-to-run sd / 2).
TEST_F(RoomAgainstRadiance, SunsWithOneBounce) {
    TempDir tmp;
    std::string four;
    {
        std::istringstream in(ReadFile(DataDir() / "rcontrib/points.txt"));
        std::string line;
        for (int i = 0; i < 4 && std::getline(in, line); ++i) four += line + "\n";
    }
    WriteFile(tmp.path() / "p4.txt", four);
    CommandResult r = RunCommand(
        "rcontrib-gpu -I+ -ab 1 -ad 1024 -lw 1e-5 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins "
        "-m solar materials.rad room.rad objects/Glazing.rad '" +
            (DataDir() / "rcontrib/suns_m6.rad").string() + "' < '" +
            (tmp.path() / "p4.txt").string() + "'",
        DataDir() / "scene/models/room");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> v = Values(r.out, true);
    ASSERT_EQ(v.size(), 4u * 5186 * 3);
    const std::vector<double> sums = RowSums(v, 4, 5186);
    const double radiance[4] = {0.0204213, 0.0148899, 0.0094011, 0.0062558};
    const double sd_ours[4] = {3.7e-5, 2.1e-5, 3.2e-5, 3.3e-5};
    const double sd_radiance[4] = {5.7e-5, 4.7e-5, 3.3e-5, 2.0e-5};
    for (int i = 0; i < 4; ++i) {
        const double tol =
            5 * std::sqrt(sd_ours[i] * sd_ours[i] + sd_radiance[i] * sd_radiance[i] / 4);
        EXPECT_NEAR(sums[i], radiance[i], tol) << "sensor " << i;
    }
}

// A seed gives the same numbers whatever the number of threads, with a patterned sky (gensky's
// skyfunc) and its sun too: every thread evaluates patterns in a context of its own.
TEST(RcontribGpu, ThreadCountDoesNotChangeResults) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", ReadFile(DataDir() / "scene/skies/gensky_clear.rad") +
                                          "skyfunc glow skyglow 0 0 4 .986 .986 1.205 0\n"
                                          "skyglow source sky 0 0 4 0 0 1 180\n");
    const std::string cmd =
        " -I+ -V+ -ab 2 -ad 256 -lw 1e-3 -faf -e MF:1 -f reinhart.cal -b rbin -bn Nrbins "
        "-m skyglow -m solar materials.rad room.rad objects/Glazing.rad '" +
        (tmp.path() / "sky.rad").string() + "' < '" + (DataDir() / "rcontrib/points.txt").string() +
        "'";
    CommandResult one = RunCommand("rcontrib-gpu -n 1" + cmd, DataDir() / "scene/models/room");
    CommandResult two = RunCommand("rcontrib-gpu -n 2" + cmd, DataDir() / "scene/models/room");
    ASSERT_EQ(one.status + two.status, 0) << one.err << two.err;
    const std::vector<double> a = Values(one.out, true), b = Values(two.out, true);
    EXPECT_EQ(a, b);
    double total = 0;
    for (double x : a) total += x;
    EXPECT_GT(total, 0);
}

// -o as rcontrib's: %s names the modifier and %d the bin; each file gets RADIANCE's header lines
// (MODIFIER=, BIN=, NCOLS= or a resolution line) and its columns of the full record.
TEST(RcontribGpu, OutputFilesPerModifierAndBin) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", std::string(kSky) +
                                          "void glow ground 0 0 4 1 1 1 0\n"
                                          "ground source floor 0 0 4 0 0 -1 180\n");
    WriteFile(tmp.path() / "pts", "0 0 0 0 0 1\n0 0 0 1 0 0\n");
    const std::string opts =
        " -I+ -ab 1 -ad 100 -y 2 -f tregenza.cal -b tbin -bn Ntbins -m skyglow -b 0 -bn 1 "
        "-m ground sky.rad < pts";
    CommandResult all = RunCommand("rcontrib-gpu -h" + opts, tmp.path());
    ASSERT_EQ(all.status, 0) << all.err;
    CommandResult r = RunCommand("rcontrib-gpu -o 'b_%s_%03d.txt'" + opts, tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    int files = 0;
    for (const auto &e : fs::directory_iterator(tmp.path()))
        files += e.path().filename().string().rfind("b_", 0) == 0;
    EXPECT_EQ(files, 146 + 1);
    const std::string bin7 = ReadFile(tmp.path() / "b_skyglow_007.txt");
    for (const char *line : {"MODIFIER=skyglow\n", "BIN=7\n", "NROWS=2\n", "NCOLS=1\n"})
        EXPECT_NE(bin7.find(line), std::string::npos) << line << bin7;
    // The same numbers as columns 7 (skyglow bin 7) and 146 (ground) of the combined record.
    const std::vector<double> v = Values("\n\n" + all.out, false);
    ASSERT_EQ(v.size(), 2u * 147 * 3);
    const std::vector<double> f7 = Values(bin7, false);
    const std::vector<double> fg = Values(ReadFile(tmp.path() / "b_ground_000.txt"), false);
    ASSERT_EQ(f7.size(), 6u);
    ASSERT_EQ(fg.size(), 6u);
    for (int row = 0; row < 2; ++row) {
        EXPECT_EQ(f7[3 * row], v[row * 147 * 3 + 7 * 3]);
        EXPECT_EQ(fg[3 * row], v[row * 147 * 3 + 146 * 3]);
    }
    EXPECT_GT(fg[3], 0);  // the sideways sensor sees the ground
    // Existing files are kept unless -fo.
    r = RunCommand("rcontrib-gpu -o 'b_%s_%03d.txt'" + opts, tmp.path());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("b_skyglow_000.txt' for writing: file exists"), std::string::npos)
        << r.err;
    r = RunCommand("rcontrib-gpu -fo+ -o 'one_%s.txt'" + opts, tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(ReadFile(tmp.path() / "one_skyglow.txt").find("NCOLS=146\n"), std::string::npos);
    r = RunCommand("rcontrib-gpu -o 'x_%f.txt'" + opts, tmp.path());
    EXPECT_NE(r.err.find("bad output format 'x_%f.txt'"), std::string::npos) << r.err;
}

// The ray variables are built in, as in RADIANCE, so a RADIANCE rayinit.cal earlier on RAYPATH
// (which does not define Dx, Dy, Dz) works too.
TEST(RcontribGpu, RadianceRayinitOnRaypath) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", kSky);
    WriteFile(tmp.path() / "rayinit.cal",
              "{ like RADIANCE's: constants, no ray variables }\n"
              "PI : 3.14159265358979323846;\nDEGREE : PI/180;\nFTINY : 1e-7;\n");
    CommandResult r = RunCommand(
        "echo '0 0 0 0 0 1' | RAYPATH=. rcontrib-gpu -I+ -ab 1 -ad 100 -h -f tregenza.cal -b tbin "
        "-bn Ntbins -m skyglow sky.rad",
        tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> v = Values("\n\n" + r.out, false);
    ASSERT_EQ(v.size(), 146u * 3);
    double total = 0;
    for (size_t i = 0; i < v.size(); i += 3) total += v[i];
    EXPECT_NEAR(total, M_PI, 1e-5);
}

// -fac with -x -y and a one-column output: a RADIANCE picture (header, resolution line, one flat
// RGBE pixel per record), holding the ascii run's values to RGBE precision (1/256).
TEST(RcontribGpu, PictureOutput) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", kSky);
    std::string rays;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            rays += "0 0 0 " + std::to_string(x - 1.5) + " 1 " + std::to_string(y - 1.0) + "\n";
    WriteFile(tmp.path() / "rays", rays);
    const std::string opts = " -I+ -ab 1 -ad 256 -x 4 -y 3 -m skyglow sky.rad < rays";
    CommandResult r = RunCommand("rcontrib-gpu -fac -o 'pic_%s.hdr'" + opts, tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string pic = ReadFile(tmp.path() / "pic_skyglow.hdr");
    const size_t body = pic.find("\n\n-Y 3 +X 4\n");
    ASSERT_NE(body, std::string::npos) << pic.substr(0, 400);
    EXPECT_NE(pic.find("FORMAT=32-bit_rle_rgbe\n"), std::string::npos);
    const std::string pixels = pic.substr(body + 12);
    ASSERT_EQ(pixels.size(), 12u * 4);
    // The ascii run: without a header but, being one column with -x and -y, with the resolution
    // line, as rcontrib writes it.
    r = RunCommand("rcontrib-gpu -h -faa" + opts, tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_EQ(r.out.rfind("-Y 3 +X 4\n", 0), 0u) << r.out.substr(0, 40);
    const std::vector<double> v = Values("\n\n" + r.out.substr(10), false);
    ASSERT_EQ(v.size(), 12u * 3);
    for (int i = 0; i < 12; ++i) {
        const auto *p = reinterpret_cast<const unsigned char *>(pixels.data() + 4 * i);
        const double red = p[3] ? (p[0] + .5) * std::ldexp(1.0, p[3] - 136) : 0;
        EXPECT_NEAR(red, v[3 * i], v[3 * i] / 128 + 1e-12) << i;
    }
}

TEST(RcontribGpu, BadInput) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", kSky);
    WriteFile(tmp.path() / "bsdf.rad", std::string(kSky) +
                                           "void BSDF shade 6 0 a.xml 0 0 1 . 0 0\n"
                                           "shade polygon p 0 0 9 0 0 1 1 0 1 0 1 1\n");
    CommandResult r =
        RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -q -m skyglow sky.rad", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("unknown option '-q'"), std::string::npos) << r.err;
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -asub 0 -m skyglow sky.rad", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("-asub: a whole number of 1 or more"), std::string::npos) << r.err;
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu sky.rad", tmp.path());
    EXPECT_NE(r.err.find("no modifiers given"), std::string::npos) << r.err;
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -m skyglow -m skyglow sky.rad", tmp.path());
    EXPECT_NE(r.err.find("duplicate modifier 'skyglow'"), std::string::npos) << r.err;
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -m skyglow bsdf.rad", tmp.path());
    EXPECT_NE(r.err.find("bsdf.rad:3: BSDF 'shade': cannot find 'a.xml' on RAYPATH"),
              std::string::npos)
        << r.err;
    WriteFile(tmp.path() / "absdf.rad", std::string(kSky) +
                                            "void aBSDF shade 5 a.xml 0 0 1 . 0 0\n"
                                            "shade polygon p 0 0 9 0 0 1 1 0 1 0 1 1\n");
    WriteFile(tmp.path() / "cone.rad",
              "void light l 0 0 3 1 1 1\nl cone c 0 0 8 0 0 2 0 0 3 .5 .2\n");
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -m l cone.rad", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("cone.rad:2: cone 'c': illegal material for a light source"),
              std::string::npos)
        << r.err;
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -m skyglow absdf.rad", tmp.path());
    EXPECT_NE(r.err.find("absdf.rad:3: aBSDF 'shade': cannot find 'a.xml' on RAYPATH"),
              std::string::npos)
        << r.err;
    WriteFile(tmp.path() / "absdf4.rad", std::string(kSky) +
                                             "void aBSDF shade 4 a.xml 0 0 1 0 0\n"
                                             "shade polygon p 0 0 9 0 0 1 1 0 1 0 1 1\n");
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -I+ -m skyglow absdf4.rad", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("absdf4.rad:3: aBSDF 'shade' needs 5+ strings"), std::string::npos)
        << r.err;
    r = RunCommand("echo '0 0 0 0 0' | rcontrib-gpu -y 1 -m skyglow sky.rad", tmp.path());
    EXPECT_NE(r.status, 0);
    r = RunCommand("echo '0 0 0 0 0 1' | rcontrib-gpu -m skyglow nosuch.rad", tmp.path());
    EXPECT_NE(r.err.find("nosuch.rad"), std::string::npos) << r.err;
}

// Light from the ground reaches sensors in a side-lit office only after a bounce (ceiling,
// reveals). RADIANCE draws again any hemisphere sample within a quarter division of an earlier
// neighbour's (ambcollision()), which moves this component by about 3 %: without the same rule
// our ground bin was 3.3 % low here (z about -6). Against the mean of 10 RADIANCE runs, within 4
// combined standard errors (ours from -se, summed over the sensors as independent).
TEST(RcontribGpu, BouncedGroundLightMatchesRadiance) {
    const fs::path dir = DataDir() / "rcontrib" / "office_open";
    std::map<std::string, std::pair<double, double>> ref;
    {
        std::istringstream in(ReadFile(dir / "radiance.txt"));
        for (std::string line; std::getline(in, line);) {
            if (line.empty() || line[0] == '#') continue;
            std::istringstream f(line);
            std::string name;
            double mean, se;
            f >> name >> mean >> se;
            ref[name] = {mean, se};
        }
    }
    ASSERT_EQ(ref.size(), 2u);
    TempDir tmp;
    const std::string cmd = "rcontrib-gpu -h -I+ -ab 2 -ad 16384 -lw 1e-7 -faa -seed 3 -se '" +
                            (tmp.path() / "se.txt").string() +
                            "' -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow "
                            "materials.rad office.rad sky.rad < sensors.pts";
    const std::vector<double> v = RunForValues(cmd, dir);
    const std::vector<double> se = Values("\n\n" + ReadFile(tmp.path() / "se.txt"), false);
    ASSERT_EQ(v.size(), 26u * 146 * 3);
    ASSERT_EQ(se.size(), v.size());
    double sum[2] = {0, 0}, var[2] = {0, 0};  // ground, sky (red channel)
    for (size_t row = 0; row < 26; ++row)
        for (size_t bin = 0; bin < 146; ++bin) {
            const size_t i = (row * 146 + bin) * 3;
            sum[bin > 0] += v[i];
            var[bin > 0] += se[i] * se[i];
        }
    const char *names[2] = {"ground", "sky"};
    for (int k = 0; k < 2; ++k) {
        const auto [mean, ref_se] = ref[names[k]];
        const double tol = 4 * std::sqrt(var[k] + ref_se * ref_se);
        EXPECT_NEAR(sum[k], mean, tol) << names[k];
        EXPECT_LT(tol, 0.025 * mean) << names[k] << ": the test must be able to see a 3 % bias";
    }
}

// The window as a Klems BSDF of venetian blinds against RADIANCE 5.4 (12 runs each,
// rcontrib/bsdf_room/radiance.txt): daylight coefficients through it (specular samples from the
// matrix, its Lambertian part as ambient), the same as a proxy 0.05 thick that hides a black
// panel behind it, and sun coefficients in the black room (the sources through the BSDF). Each
// sensor is traced 2 or 5 times and averaged (-c); tolerance 4 combined standard errors.
TEST(RcontribGpu, KlemsBsdfWindowAsRadiance) {
    const fs::path dir = DataDir() / "rcontrib/bsdf_room";
    std::map<std::string, std::array<double, 3>> ref;
    {
        std::istringstream in(ReadFile(dir / "radiance.txt"));
        for (std::string line; std::getline(in, line);) {
            if (line.empty() || line[0] == '#') continue;
            std::istringstream f(line);
            std::string name;
            std::array<double, 3> v;
            f >> name >> v[0] >> v[1] >> v[2];
            ref[name] = v;
        }
    }
    ASSERT_EQ(ref.size(), 3u);
    TempDir tmp;
    ASSERT_EQ(RunCommand("xz -dc '" + (dir / "frads_blinds30.xml.xz").string() + "' > '" +
                             (tmp.path() / "frads_blinds30.xml").string() + "'",
                         tmp.path())
                  .status,
              0);
    const auto replicated = [&](int reps) {  // each sensor `reps` times, for -c
        std::ostringstream points;
        std::istringstream in(ReadFile(DataDir() / "rcontrib/points.txt"));
        for (std::string line; std::getline(in, line);)
            if (!line.empty())
                for (int k = 0; k < reps; ++k) points << line << "\n";
        const fs::path file = tmp.path() / ("points" + std::to_string(reps) + ".txt");
        WriteFile(file, points.str());
        return file.string();
    };
    const std::string common =
        "RAYPATH='" + tmp.path().string() + "' rcontrib-gpu -h -seed 5 -I+ -faa ";
    const std::string dc =
        "-ab 2 -ad 2048 -lw 1e-5 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow "
        "-m groundglow materials.rad room.rad skyDomes/skyglow.rad '";
    const std::string cds =
        "-ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -e MF:6 -f reinhart.cal -b rbin -bn Nrbins "
        "-m solar materialBlack.rad roomBlack.rad '" +
        (DataDir() / "rcontrib/suns_m6.rad").string() + "' '";
    const std::map<std::string, std::pair<std::string, int>> runs = {
        {"dc", {dc + (dir / "blinds.rad").string() + "'", 2}},
        {"proxy", {dc + (dir / "blinds_proxy.rad").string() + "'", 2}},
        {"cds", {cds + (dir / "blinds.rad").string() + "'", 5}}};
    for (const auto &[name, run] : runs) {
        const auto &[args, reps] = run;
        const std::vector<double> v = RunForValues(
            common + "-c " + std::to_string(reps) + " " + args + " < '" + replicated(reps) + "'",
            DataDir() / "scene/models/room");
        ASSERT_EQ(v.size() % 300, 0u) << name;
        double total = 0;  // -c averages its rays
        for (size_t i = 0; i < v.size(); i += 3) total += v[i];
        const auto [mean, se, sd] = ref[name];
        const double tol = 4 * std::sqrt(sd * sd / reps + se * se);
        EXPECT_NEAR(total, mean, tol) << name;
        // Sun coefficients are noisier (16 x 16 hemisphere rays per sensor, -ad 256).
        EXPECT_LT(tol, (name == "cds" ? 0.04 : 0.015) * mean)
            << name << ": too loose to see a bias";
    }
}

// -ss 4: a view ray meeting a rough metal (all specular) sends 4 Gaussian samples, each with a
// quarter of the coefficient, as rcontrib does. Every ray's total is still the metal's colour,
// the split between two sky bins has the same mean as with one sample, and a quarter of the
// variance (a per-sample coefficient left whole would make the total 4 x .6).
TEST(RcontribGpu, SeveralSpecularSamples) {
    TempDir tmp;
    WriteFile(tmp.path() / "scene.rad",
              std::string(kSky) +
                  "void metal f 0 0 5 .6 .5 .4 1 .2\n"
                  "f polygon floor 0 0 12 -50 -50 0 50 -50 0 50 50 0 -50 50 0\n");
    std::ostringstream rays;
    const int n = 4000;
    for (int i = 0; i < n; ++i) rays << "0 -1 1 0 0.7 -0.7\n";
    WriteFile(tmp.path() / "rays.txt", rays.str());
    double mean[2], var[2];
    for (int k = 0; k < 2; ++k) {
        const std::vector<double> v =
            RunForValues(std::string("rcontrib-gpu -h -faa -ab 0 -seed 2 -ss ") + (k ? "4" : "1") +
                             " -b 'if(Dz-.7071,1,0)' -bn 2 -m skyglow scene.rad < rays.txt",
                         tmp.path());
        ASSERT_EQ(v.size(), 6u * n);
        double s = 0, s2 = 0;
        for (int i = 0; i < n; ++i) {
            ASSERT_NEAR(v[6 * i] + v[6 * i + 3], .6, 1e-9) << i;
            s += v[6 * i + 3], s2 += v[6 * i + 3] * v[6 * i + 3];
        }
        mean[k] = s / n;
        var[k] = s2 / n - mean[k] * mean[k];
    }
    ASSERT_GT(var[0], 0.01);  // both bins are reached
    EXPECT_NEAR(mean[1], mean[0], 4 * std::sqrt((var[0] + var[1]) / n));
    // Sample variances of n draws have a relative standard error of about sqrt(2 / n).
    EXPECT_NEAR(var[1] / var[0], .25, .25 * 5 * std::sqrt(4. / n));
}

// A slab of dielectric (n 1.33) over two sensors. The sun's shadow rays refract in and out
// (parallel faces: the same direction), so with -dj 0 a sensor gets ldot x solid angle x
// (1 - R)^2, R from Fresnel's equations, as RADIANCE 5.4 computes it to the last digit. The
// sky through the slab at -ab 3 against RADIANCE (8 runs: 2.85626, standard error 0.00095; one
// run of ours has a standard deviation of 0.0025). The colour (an extinction per unit length)
// stays out of contributions, as in rcontrib, with its warning.
TEST(RcontribGpu, DielectricAsRadiance) {
    TempDir tmp;
    const double *sun = kSlabSun;
    WriteFile(tmp.path() / "slab.rad", DielectricSlab());
    const CommandResult r = RunCommand(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -dj 0 -I+ -ab 0 -faa -h -m solar slab.rad", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("does not support participating media"), std::string::npos) << r.err;
    const std::vector<double> v = Values("\n\n" + r.out, false);
    ASSERT_EQ(v.size(), 3u);
    const double l = std::sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
    const double c1 = sun[2] / l, n = 1.33;
    const double c2 = std::sqrt(1 - (1 - c1 * c1) / (n * n));
    const double rs = (c1 - n * c2) / (c1 + n * c2), rp = (c2 - n * c1) / (c2 + n * c1);
    const double fresnel = .5 * (rs * rs + rp * rp);
    const double omega = 2 * M_PI * (1 - std::cos(0.533 / 2 * M_PI / 180));
    const double expect = c1 * omega * (1 - fresnel) * (1 - fresnel);
    EXPECT_NEAR(v[0], expect, 1e-6 * expect);
    EXPECT_NEAR(v[0], 5.247752e-05, 1e-6 * expect);  // RADIANCE's own
    EXPECT_EQ(v[0], v[2]);                           // grey: no extinction
    const std::vector<double> sky = RunForValues(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -seed 4 -I+ -ab 3 -ad 4096 -lw 1e-6 -faa -h "
        "-m skyglow slab.rad 2> /dev/null",
        tmp.path());
    ASSERT_EQ(sky.size(), 3u);
    EXPECT_NEAR(sky[0], 2.85626, 4 * std::sqrt(0.0025 * 0.0025 + 0.00095 * 0.00095));
}

// -o applies to the modifiers after it, as in RADIANCE: each modifier's columns go where the -o
// before it says (the standard output where none does), and an -o after the last is warned about.
// (The ray looks straight up at the sky of radiance 1.)
TEST(RcontribGpu, OutputSpecAppliesToTheModifiersAfterIt) {
    TempDir tmp;
    WriteFile(tmp.path() / "s.rad", std::string(kSky) +
                                        "void glow groundglow 0 0 4 1 1 1 0\n"
                                        "groundglow source ground 0 0 4 0 0 -1 180\n");
    WriteFile(tmp.path() / "rays", "0 0 0 0 0 1\n");
    CommandResult r = RunCommand(
        "rcontrib-gpu -h -ab 0 -m groundglow -o sky.txt -m skyglow s.rad < rays", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "0.000000e+00\t0.000000e+00\t0.000000e+00\t\n");
    EXPECT_EQ(ReadFile(tmp.path() / "sky.txt").substr(0, 12), "1.000000e+00");
    r = RunCommand("rcontrib-gpu -h -ab 0 -m skyglow -o late.txt s.rad < rays", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("-o late.txt after the last modifier has no effect"), std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "late.txt"));
    EXPECT_EQ(r.out.substr(0, 12), "1.000000e+00");
}

// -r: an output cut short (4 records and part of a fifth) is completed from the input ray after
// the last whole record, and ends byte for byte as the uninterrupted run (random numbers are
// keyed by the input ray); what rcontrib cannot recover is refused as it refuses it.
TEST(RcontribGpu, RecoverContinuesAnInterruptedRun) {
    TempDir tmp;
    WriteFile(tmp.path() / "s.rad", std::string(kSky) +
                                        "void plastic w 0 0 5 .5 .5 .5 0 0\n"
                                        "w polygon p 0 0 12 -1 -1 1 1 -1 1 1 1 1.5 -1 1 1.5\n");
    std::ostringstream pts;
    for (int i = 1; i <= 20; ++i) pts << "0 0 0 0 " << i / 40.0 << " 1\n";
    WriteFile(tmp.path() / "pts.txt", pts.str());
    const auto run = [](const std::string &options) {
        return "rcontrib-gpu -seed 3 -faf -c 2 -I+ -ab 2 -ad 256 -f tregenza.cal -b tbin "
               "-bn Ntbins " +
               options + " -m skyglow s.rad < pts.txt";
    };
    ASSERT_EQ(RunCommand(run("-o full_%s.fmx"), tmp.path()).status, 0);
    const std::string full = ReadFile(tmp.path() / "full_skyglow.fmx");
    const size_t header = full.find("\n\n") + 2, record = 146 * 12;
    ASSERT_EQ(full.size(), header + 10 * record);
    WriteFile(tmp.path() / "cut_skyglow.fmx", full.substr(0, header + 4 * record + 100));
    CommandResult r = RunCommand(run("-r -o cut_%s.fmx"), tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(ReadFile(tmp.path() / "cut_skyglow.fmx") == full);
    // Complete already (-y says how many records): nothing to do.
    r = RunCommand(run("-y 10 -r -o full_%s.fmx"), tmp.path());
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.err.find("output appears to be complete"), std::string::npos) << r.err;
    EXPECT_TRUE(ReadFile(tmp.path() / "full_skyglow.fmx") == full);
    r = RunCommand(run("-r -fad -o full_%s.fmx"), tmp.path());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("format mismatch for 'full_skyglow.fmx'"), std::string::npos) << r.err;
    r = RunCommand(run("-r -faa -o full_%s.fmx"), tmp.path());
    EXPECT_NE(r.err.find("cannot recover ASCII output"), std::string::npos) << r.err;
    r = RunCommand(run("-r"), tmp.path());
    EXPECT_NE(r.err.find("cannot recover from stdout"), std::string::npos) << r.err;
}

// A square light source (side .5, radiance 1) 1 m above a sensor facing it: with -dj 1 every
// part of the source is sampled uniformly, so the estimate is the exact configuration factor
// times pi, 2 (X atan(X / sqrt(1 + X^2)) / sqrt(1 + X^2)) x 2 for X = .25 / h, whole (-ds 0) or
// split by -ds, or put in place by xform; a sensor behind the source gets nothing. 4 standard
// errors of 2000 rays.
TEST(RcontribGpu, LocalLightIsItsFormFactor) {
    TempDir tmp;
    WriteFile(tmp.path() / "lamp.rad",
              "void light lamp 0 0 3 1 1 1\n"
              "lamp polygon panel 0 0 12 -.25 -.25 1 -.25 .25 1 .25 .25 1 .25 -.25 1\n");
    WriteFile(tmp.path() / "panel.rad",
              "lamp polygon panel 0 0 12 -.25 .25 0 -.25 -.25 0 .25 -.25 0 .25 .25 0\n");
    WriteFile(tmp.path() / "moved.rad",
              "void light lamp 0 0 3 1 1 1\n!xform -rx 180 -t 0 0 1 panel.rad\n");
    std::ostringstream rays;
    for (int i = 0; i < 2000; ++i) rays << "0 0 0 0 0 1\n";
    rays << "0 0 2 0 0 -1\n";
    WriteFile(tmp.path() / "rays.txt", rays.str());
    const double x = .25 / (1 - 1e-4), q = std::sqrt(1 + x * x);  // -I starts 1e-4 up
    const double expect = 4 * x / q * std::atan(x / q);
    const std::pair<std::string, std::string> runs[] = {
        {"0", "lamp.rad"}, {".2", "lamp.rad"}, {".02", "lamp.rad"}, {"0", "moved.rad"}};
    for (const auto &[ds, scene] : runs) {
        const std::vector<double> v =
            RunForValues("rcontrib-gpu -h -faa -I+ -ab 0 -dj 1 -seed 8 -ds " + ds + " -m lamp " +
                             scene + " < rays.txt",
                         tmp.path());
        ASSERT_EQ(v.size(), 3u * 2001);
        std::vector<double> e;
        for (int i = 0; i < 2000; ++i) e.push_back(v[3 * i]);
        double mean, se;
        MeanAndStandardError(e, &mean, &se);
        EXPECT_NEAR(mean, expect, 4 * se) << "-ds " << ds << " " << scene;
        EXPECT_LT(se, 0.003 * expect);
        EXPECT_EQ(v[3 * 2000], 0.) << "behind the source";
    }
}

// Mirrors relay sources (RADIANCE's virtual sources, -dr): a sun seen in a mirror shelf, and in
// a mirror wall then the shelf, by sensors under a ceiling (-dj 0: exactly the mirrors' colours,
// once or twice, times the cosine and the sun's solid angle; checked by hand against RADIANCE
// 5.4, which gives the same to its 4 digits); -dr 1 keeps only the first, -dr 0 neither. A
// lamp seen in a mirror floor is its image's form factor times the mirror's reflectance. The
// back of a mirror is black; a mirror naming void as its substitute lets rays aimed at other
// sources through.
TEST(RcontribGpu, MirrorsRelaySources) {
    TempDir tmp;
    WriteFile(tmp.path() / "shelf.rad",
              "void light solar 0 0 3 1e6 1e6 1e6\n"
              "solar source sun 0 0 4 0.3 -1 1.2 0.533\n"
              "void plastic white 0 0 5 .7 .7 .7 0 0\n"
              "white polygon ceiling 0 0 12 -3 -3 4 3 -3 4 3 3 4 -3 3 4\n"
              "void mirror silver 0 0 3 .85 .8 .75\n"
              "silver polygon shelf 0 0 12 -2 -2 1  2 -2 1  2 0 1  -2 0 1\n"
              "silver polygon wall 0 0 12 -3 1 0  3 1 0  3 1 4  -3 1 4\n"
              "void plastic black 0 0 5 0 0 0 0 0\n"
              "black polygon strip 0 0 12 -3 -.5 2 3 -.5 2 3 .2 2 -3 .2 2\n");
    // Unlit, lit twice over (wall, shelf), lit by the shelf, lit both ways.
    WriteFile(tmp.path() / "sensors.txt",
              ".1 -.5 3.95 0 0 -1\n.1 .1 3.95 0 0 -1\n.1 .65 3.95 0 0 -1\n.1 .95 3.95 0 0 -1\n");
    const double cosine = 1.2 / std::sqrt(.09 + 1 + 1.44);
    const double omega = 2 * M_PI * (1 - std::cos(.533 / 2 * M_PI / 180));
    const double colour[3] = {.85, .8, .75};
    for (int dr : {3, 1, 0}) {
        const std::vector<double> v =
            RunForValues("rcontrib-gpu -h -faa -I+ -ab 0 -dj 0 -dr " + std::to_string(dr) +
                             " -m solar shelf.rad < sensors.txt",
                         tmp.path());
        ASSERT_EQ(v.size(), 12u);
        for (int c = 0; c < 3; ++c) {
            const double once = dr >= 1 ? colour[c] * cosine * omega : 0;
            const double twice = dr >= 2 ? colour[c] * colour[c] * cosine * omega : 0;
            EXPECT_EQ(v[c], 0) << "-dr " << dr;
            EXPECT_NEAR(v[3 + c], twice, 1e-6 * omega) << "-dr " << dr;
            EXPECT_NEAR(v[6 + c], once, 1e-6 * omega) << "-dr " << dr;
            EXPECT_NEAR(v[9 + c], once + twice, 1e-6 * omega) << "-dr " << dr;
        }
    }

    WriteFile(tmp.path() / "floor.rad",
              "void light lamp 0 0 3 1 1 1\n"
              "lamp polygon panel 0 0 12 -.25 -.25 2 -.25 .25 2 .25 .25 2 .25 -.25 2\n"
              "void mirror silver 0 0 3 .8 .8 .8\n"
              "silver polygon floor 0 0 12 -2 -2 0 2 -2 0 2 2 0 -2 2 0\n");
    std::ostringstream rays;
    for (int i = 0; i < 2000; ++i) rays << "0 0 1 0 0 -1\n";
    WriteFile(tmp.path() / "down.txt", rays.str());
    std::vector<double> v = RunForValues(
        "rcontrib-gpu -h -faa -I+ -ab 0 -dj 1 -seed 3 -m lamp floor.rad < down.txt", tmp.path());
    ASSERT_EQ(v.size(), 3u * 2000);
    std::vector<double> e;
    for (int i = 0; i < 2000; ++i) e.push_back(v[3 * i]);
    double mean, se;
    MeanAndStandardError(e, &mean, &se);
    const double x = .25 / (3 - 1e-4), q = std::sqrt(1 + x * x);  // the image is 3 m away
    EXPECT_NEAR(mean, .8 * 4 * x / q * std::atan(x / q), 4 * se);
    EXPECT_LT(se, 0.003 * mean);

    // A glow floor under the mirror's back: a sensor between them facing up sees black; the sun
    // reaches a sensor under a mirror whose substitute is void, not one under a plain mirror.
    WriteFile(tmp.path() / "back.rad",
              "void glow floorglow 0 0 4 1 1 1 0\n"
              "floorglow polygon ground 0 0 12 -50 -50 0 -50 50 0 50 50 0 50 -50 0\n"
              "void mirror plain 0 0 3 .9 .9 .9\n"
              "plain polygon roof 0 0 12 -50 -50 1 50 -50 1 50 50 1 -50 50 1\n");
    v = RunForValues(
        "echo '0 0 .5 0 0 1' | rcontrib-gpu -h -faa -I+ -ab 1 -ad 64 -m floorglow "
        "back.rad",
        tmp.path());
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0], 0) << "the back of a mirror is black";
    for (const char *sub : {"0", "1 void"}) {
        WriteFile(tmp.path() / "sub.rad",
                  "void light solar 0 0 3 1e6 1e6 1e6\nsolar source sun 0 0 4 0 0 1 0.533\n"
                  "void mirror m " +
                      std::string(sub) +
                      " 0 3 .9 .9 .9\nm polygon roof 0 0 12 -5 -5 1 5 -5 1 5 5 1 -5 5 1\n");
        v = RunForValues(
            "echo '0 0 .5 0 0 1' | rcontrib-gpu -h -faa -I+ -ab 0 -dj 0 -m solar sub.rad",
            tmp.path());
        ASSERT_EQ(v.size(), 3u);
        EXPECT_NEAR(v[0], sub[0] == '0' ? 0 : omega, 1e-6 * omega) << "mirror " << sub;
    }
}

// A spotlight put in place by xform keeps its cone about the transformed focus vector (turned
// down here, as RADIANCE's xform turns it), and its focus distance (1 m) moves the point its
// solid angle is seen from: a 20 cm panel 2 m up gives nearly .04 / 3^2. (RADIANCE 5.4:
// 4.434e-3.)
TEST(RcontribGpu, SpotlightUnderXform) {
    TempDir tmp;
    WriteFile(tmp.path() / "spot.rad",
              "void spotlight sp 0 0 7 100 100 100 40 0 0 1\n"
              "sp polygon panel 0 0 12 -.1 .1 0 -.1 -.1 0 .1 -.1 0 .1 .1 0\n");
    WriteFile(tmp.path() / "turned.rad", "!xform -rx 180 -t 0 0 2 spot.rad\n");
    const std::vector<double> v = RunForValues(
        "echo '0 0 0 0 0 1' | rcontrib-gpu -h -faa -I+ -ab 0 -c 400 -m sp turned.rad", tmp.path());
    ASSERT_EQ(v.size(), 3u);
    EXPECT_NEAR(v[0], .04 / 9, .005 * .04 / 9);
}

// Each sensor ray ("x y z dx dy dz") written `reps` times to dir/name, for -c `reps`.
std::string ReplicatedSensors(const fs::path &dir, const std::string &name,
                              const std::vector<std::string> &sensors, int reps) {
    std::ostringstream rays;
    for (const std::string &p : sensors)
        for (int i = 0; i < reps; ++i) rays << p << "\n";
    WriteFile(dir / name, rays.str());
    return name;
}

// One of our results against RADIANCE's mean (se: its standard error) within 4 combined standard
// errors (sd: the standard deviation of one of our runs), tight enough to see a bias of `see`.
void ExpectAsRadiance(double ours, double mean, double se, double sd, const std::string &what,
                      double see = 0.02) {
    const double tol = 4 * std::sqrt(se * se + sd * sd);
    EXPECT_NEAR(ours, mean, tol) << what;
    EXPECT_LT(tol, see * mean) << what;
}

// Local sources against RADIANCE 5.4 (-ab 0 -dj .9 -ds .2; 14 runs for the lamps, 6 for the
// others): two light polygons facing down, a square and a hexagon (sampled over a square of its
// area that RADIANCE turns at random), a sphere and a disc (ring), seen by four sensors, each
// traced 200 times (-c). Then a window of illum (void: transparent from behind) in a room with
// a glow sky: the illum is sampled as a source, ambient rays meeting it from inside count
// nothing (8 RADIANCE runs, -ab 2 -ad 256). Totals over the sensors; tolerance 4 x the
// combined standard error (one of our runs: its standard deviation over 8 seeds).
TEST(RcontribGpu, LocalSourcesAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", LocalSourcesRoom());
    WriteFile(tmp.path() / "illum.rad",
              "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n" +
                  test::IllumWindowRoom() +
                  "void glass clear 0 0 3 .9 .9 .9\n"
                  "clear polygon pane 0 0 12  1 -0.01 1  1 -0.01 2  4 -0.01 2  4 -0.01 1\n");
    ReplicatedSensors(tmp.path(), "pts.txt",
                      {"2.5 2 0.8 0 0 1", "1 1 0.8 0 0 1", "4 3 0.8 0 0 1", "0.5 3.5 1 1 0 0"},
                      200);
    ReplicatedSensors(tmp.path(), "ipts.txt",
                      {"2.5 2 0.8 0 0 1", "1 1 0.8 0 0 1", "2.5 1 1.5 0 -1 0"}, 100);
    const auto totals = [](const std::vector<double> &v, int rows, int mods) {
        std::vector<double> t(mods, 0.);
        for (int r = 0; r < rows; ++r)
            for (int m = 0; m < mods; ++m) t[m] += v[3 * (r * mods + m)];
        return t;
    };
    std::vector<double> v = RunForValues(
        "rcontrib-gpu -c 200 -seed 1 -I+ -ab 0 -faa -h -m lamp -m bulb -m disc room.rad "
        "< pts.txt",
        tmp.path());
    ASSERT_EQ(v.size(), 4u * 9);
    std::vector<double> t = totals(v, 4, 3);
    ExpectAsRadiance(t[0], 0.443048, 0.00016, 0.00088, "lamps");
    ExpectAsRadiance(t[1], 0.0270245, 7.1e-05, 0.0001, "sphere");
    ExpectAsRadiance(t[2], 0.0404604, 1.5e-05, 4.9e-05, "disc");
    v = RunForValues(
        "rcontrib-gpu -c 100 -seed 1 -I+ -ab 2 -ad 256 -lw 1e-5 -faa -h -m winillum -m skyglow "
        "-m wall illum.rad < ipts.txt",
        tmp.path());
    ASSERT_EQ(v.size(), 3u * 9);
    t = totals(v, 3, 3);
    ExpectAsRadiance(t[0], 1.88713, 0.00069, 0.00096, "illum");
    EXPECT_LT(t[1], 1e-4) << "the sky is seen only through the illum, which ambient rays may not";
    ExpectAsRadiance(t[2], 11.4688, 0.0015, 0.0058, "walls");
}

// Shadow rays aimed at another source pass an illum without counting for it (trace_contrib():
// a ray aimed at a source counts only there): a lamp behind an illum window leaves the illum's
// coefficients as they are without the lamp (same seed, and the lamp's samples come after).
TEST(RcontribGpu, IllumCountsOnlyItsOwnRays) {
    TempDir tmp;
    const std::string illum =
        "void illum win 0 0 3 1 1 1\nwin polygon w 0 0 12 -1 -1 2 -1 1 2 1 1 2 1 -1 2\n";
    WriteFile(tmp.path() / "illum.rad", illum);
    WriteFile(tmp.path() / "both.rad",
              illum +
                  "void light lamp 0 0 3 5 5 5\n"
                  "lamp polygon l 0 0 12 -.5 -.5 3 -.5 .5 3 .5 .5 3 .5 -.5 3\n");
    const std::string run =
        "echo '0 0 0 0 0 1' | rcontrib-gpu -h -faa -I+ -ab 0 -seed 3 -m win -m lamp ";
    const std::vector<double> alone = RunForValues(run + "illum.rad", tmp.path());
    const std::vector<double> both = RunForValues(run + "both.rad", tmp.path());
    ASSERT_EQ(alone.size(), 6u);
    ASSERT_EQ(both.size(), 6u);
    EXPECT_GT(alone[0], 0);
    EXPECT_EQ(both[0], alone[0]);
    EXPECT_GT(both[3], 0) << "the lamp is seen through the illum";
}

// Spotlights (two 0.4 m squares with a 60 degree cone and a focus 2 m behind them) over a floor,
// against RADIANCE 5.4 (-ab 0 -dj .9, 6 runs of 200 rays per sensor): a sensor under each, one
// between them, and one outside both cones, which gets nothing.
TEST(RcontribGpu, SpotlightsAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "spot.rad",
              "void plastic wall 0 0 5 .5 .5 .5 0 0\n"
              "wall polygon floor 0 0 12  -5 -5 0  -5 5 0  5 5 0  5 -5 0\n"
              "void spotlight spot 0 0 7 100 100 100 60 0 0 -2\n"
              "spot polygon lamp 0 0 12  -.2 -.2 3  -.2 .2 3  .2 .2 3  .2 -.2 3\n"
              "spot polygon lamp2 0 0 12  1.8 -.2 3  1.8 .2 3  2.2 .2 3  2.2 -.2 3\n");
    ReplicatedSensors(tmp.path(), "rays.txt",
                      {"0 0 0.5 0 0 1", "1 0 0.5 0 0 1", "2.5 0 0.5 0 0 1", "4 0 0.5 0 0 1"}, 200);
    const std::vector<double> v = RunForValues(
        "rcontrib-gpu -c 200 -seed 1 -I+ -ab 0 -faa -h -m spot spot.rad < rays.txt", tmp.path());
    ASSERT_EQ(v.size(), 12u);
    const double mean[3] = {0.0078594238, 0.012499692, 0.007402686};
    const double se[3] = {9.2e-07, 1.3e-05, 5.4e-06};  // RADIANCE's mean
    const double sd[3] = {2.3e-06, 2.1e-05, 8.1e-06};  // one of our runs (6 seeds)
    for (int k = 0; k < 3; ++k)
        ExpectAsRadiance(v[3 * k], mean[k], se[k], sd[k], "sensor " + std::to_string(k));
    EXPECT_EQ(v[9], 0.) << "outside both cones";
}

// A tube light (a light cylinder 2 m long, radius 2 cm) seen by four sensors, one beyond its
// open end (whose shadow rays reaching the tube from inside count nothing, as direct()
// sends none there), against RADIANCE 5.4 (-ab 0, 6 runs of 200 rays per sensor).
TEST(RcontribGpu, TubeLightAsRadiance) {
    TempDir tmp;
    WriteFile(tmp.path() / "tube.rad",
              "void light tubelight 0 0 3 20 20 20\n"
              "tubelight cylinder tube 0 0 7  -1 0 2  1 0 2  0.02\n");
    ReplicatedSensors(tmp.path(), "rays.txt",
                      {"0 0 0 0 0 1", "0.8 0.3 0 0 0 1", "2 0 1.5 -1 0 0", "0 1 1.9 0 -1 0"}, 200);
    const std::vector<double> v = RunForValues(
        "rcontrib-gpu -c 200 -seed 1 -I+ -ab 0 -faa -h -m tubelight tube.rad < rays.txt",
        tmp.path());
    ASSERT_EQ(v.size(), 12u);
    const double mean[4] = {0.01729007, 0.01388501, 0.006492543, 0.05078896};
    const double se[4] = {6e-06, 1e-05, 3e-05, 3e-05};  // RADIANCE's mean
    const double sd[4] = {9e-06, 2e-05, 5e-05, 4e-05};  // one of our runs (6 seeds)
    for (int k = 0; k < 4; ++k)                         // (beyond the end, samples are few: 4 %)
        ExpectAsRadiance(v[3 * k], mean[k], se[k], sd[k], "sensor " + std::to_string(k), 0.04);
}

}  // namespace dayflux::test
