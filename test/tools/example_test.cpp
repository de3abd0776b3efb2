// The flagship example (examples/reference-office) at a tiny size: the whole Makefile runs,
// its metrics do not depend on the thread count, and the direct-sun metric, which has no
// sampling noise (-ab 0 -dj 0), is what the geometry gives.
#include <gtest/gtest.h>
#include <unistd.h>

#include <map>
#include <sstream>

#include "matrix/matrices.h"
#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;
namespace {

// The fields of a text's last non-empty line.
std::vector<std::string> LastLineFields(const std::string &text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty()) last = line;
    std::istringstream f(last);
    std::vector<std::string> fields;
    for (std::string w; f >> w;) fields.push_back(w);
    return fields;
}

TEST(ReferenceOfficeExample, TinyRunIsStableAndPlausible) {
    const fs::path example = DataDir() / ".." / ".." / "examples" / "reference-office";
    ASSERT_TRUE(fs::exists(example / "Makefile"));
    TempDir tmp;
    const std::string common = "make -s --no-print-directory -C '" + example.string() + "' BIN='" +
                               BinDir().string() + "' NX=3 NY=5 AB=2 AD=64";
    for (const char *threads : {"1", "2"}) {
        const fs::path out = tmp.path() / (std::string("n") + threads);
        CommandResult r =
            RunCommand(common + " NPROC=" + threads + " OUT='" + out.string() + "'", tmp.path());
        ASSERT_EQ(r.status, 0) << r.err;
        for (const char *f : {"metrics.txt", "metrics.csv", "metrics.json", "da.png", "ase.png",
                              "snapshot.png", "snapshot.hdr", "snapshot.exr"})
            EXPECT_TRUE(fs::exists(out / f)) << f;
    }
    const std::string csv = ReadFile(tmp.path() / "n1" / "metrics.csv");
    EXPECT_EQ(csv, ReadFile(tmp.path() / "n2" / "metrics.csv"));
    EXPECT_EQ(ReadFile(tmp.path() / "n1" / "metrics.txt"),
              ReadFile(tmp.path() / "n2" / "metrics.txt"));

    // Sensors row by row from the window (0.82 m deep) to the back wall (7.38 m): the front
    // row gets direct sun above 1000 lux for more than 250 occupied hours, the rows from
    // 2.46 m back do not (a head 1.99 m high, 1 m above the work plane), so ASE is 3 of 15.
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    int sensor = 0;
    double front_da = 0;
    while (std::getline(lines, line)) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
        ASSERT_EQ(f.size(), 9u) << line;
        const double ase_hours = std::stod(f[8]);
        if (sensor < 3) {
            EXPECT_GT(ase_hours, 250) << line;
            front_da += std::stod(f[3]) / 3;
        } else {
            EXPECT_LT(ase_hours, 250) << line;
        }
        ++sensor;
    }
    EXPECT_EQ(sensor, 15);
    EXPECT_GT(front_da, 50);
    const std::string txt = ReadFile(tmp.path() / "n1" / "metrics.txt");
    EXPECT_NE(txt.find("3650 occupied hours"), std::string::npos) << txt;
    const std::vector<std::string> whole = LastLineFields(txt);
    ASSERT_EQ(whole.size(), 8u) << txt;
    EXPECT_EQ(whole[3], "20.0%") << txt;

    // Two offices with exterior blinds: a line per office and one for the whole; the blinds
    // shade the daylight (sDA no higher) but not ASE, which LM-83 computes without them.
    const fs::path shaded = tmp.path() / "shaded";
    CommandResult r =
        RunCommand(common + " OFFICES=2 BLINDS=1 OUT='" + shaded.string() + "'", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string two = ReadFile(shaded / "metrics.txt");
    EXPECT_NE(two.find("office1"), std::string::npos) << two;
    const std::vector<std::string> all = LastLineFields(two);
    ASSERT_EQ(all.size(), 8u) << two;
    EXPECT_EQ(all[0], "all");
    EXPECT_EQ(all[1], "30");
    EXPECT_EQ(all[3], "20.0%") << two;
    EXPECT_LE(std::stod(all[2]), std::stod(whole[2])) << two;
}

// Each sensor's illuminance summed over the year (the first component), from a .ill matrix.
std::vector<double> AnnualSums(const fs::path &ill) {
    const Matrix m = LoadMatrix(ill.string());
    std::vector<double> sums(m.rows, 0.0);
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c) sums[r] += m.at(r, c, 0);
    return sums;
}

// The three- and five-phase methods on the same tiny office (Makefile.phases, clear glazing as
// a Klems BSDF): the year's light over the sensors agrees with the daylight-coefficient run's
// within what the Klems patches and the noise allow (docs/methods.md); the five-phase method's
// direct sun is the DC run's C_ds S_sun (the same ASE hours), and the three-phase direct sun
// (V_d T D_d S_d) carries about the same energy, spread over Klems patches.
TEST(ReferenceOfficeExample, ThreeAndFivePhaseAgreeWithDaylightCoefficients) {
    const fs::path example = DataDir() / ".." / ".." / "examples" / "reference-office";
    TempDir tmp;
    const fs::path out = tmp.path() / "out";
    const std::string common = "make -s --no-print-directory -C '" + example.string() + "' BIN='" +
                               BinDir().string() + "' NX=3 NY=5 AB=3 AD=512 OUT='" + out.string() +
                               "' METHOD=";
    std::map<std::string, std::string> csv;
    for (const char *method : {"dc", "3phase", "5phase"}) {
        const CommandResult r = RunCommand(common + method, tmp.path());
        ASSERT_EQ(r.status, 0) << method << ": " << r.err;
        csv[method] = ReadFile(out / "metrics.csv");
    }
    const std::vector<double> dc = AnnualSums(out / "total.ill"),
                              three = AnnualSums(out / "total3.ill"),
                              five = AnnualSums(out / "total5.ill");
    ASSERT_EQ(dc.size(), 15u);
    double sum_dc = 0, sum_three = 0, sum_five = 0;
    for (size_t i = 0; i < dc.size(); ++i)
        sum_dc += dc[i], sum_three += three[i], sum_five += five[i];
    // Over the 15 sensors 3ph/dc is 1.06 and 5ph/dc 1.01 here; single sensors at the back,
    // lit only by interreflection, differ by up to 27 % (the noise of both runs at -ad 512).
    EXPECT_NEAR(sum_three / sum_dc, 1, 0.12);
    EXPECT_NEAR(sum_five / sum_dc, 1, 0.12);
    const std::vector<double> sun = AnnualSums(out / "direct.ill"),
                              sun3 = AnnualSums(out / "direct3.ill");
    double total_sun = 0, total_sun3 = 0;
    for (size_t i = 0; i < sun.size(); ++i) total_sun += sun[i], total_sun3 += sun3[i];
    // Klems patches spread the sun over about +-7 degrees, moving it up to a metre across rows
    // 1.6 m apart here, so five sensors see 15 % more (the 1425 of the small model 3 %).
    EXPECT_NEAR(total_sun3 / total_sun, 1, 0.25);
    // ASE hours (the last column) of the five-phase run are the DC run's, column for column.
    const auto ase_hours = [](const std::string &text) {
        std::vector<std::string> hours;
        std::istringstream lines(text);
        for (std::string line; std::getline(lines, line);)
            hours.push_back(line.substr(line.rfind(',') + 1));
        return hours;
    };
    EXPECT_EQ(ase_hours(csv["5phase"]), ase_hours(csv["dc"]));
    EXPECT_NE(ase_hours(csv["3phase"]), ase_hours(csv["dc"]));
    // With the exterior blinds: T the glass, slats, head box and guides' BSDF from genBSDF (at
    // low settings), the five-phase sun traced through the slats. The blinds take over a third of
    // the year's light, and the five-phase run agrees with the DC run, whose blinds are geometry
    // (0.99 times at the example's settings). Here the DC run's three bounces in all, through the
    // slats and the room, keep less light than T's two between the slats and V's three in the
    // room: 1.09 to 1.28 times over 14 seeds (mean 1.19, standard deviation 0.05).
    const std::string blinds = "BLINDS=1 GENBSDF_OPTS=\"-c 50 -r '-ab 2 -ad 64 -lw 1e-3'\"";
    for (const char *method : {"dc", "5phase"}) {
        const CommandResult r = RunCommand(common + method + " " + blinds, tmp.path());
        ASSERT_EQ(r.status, 0) << method << " with blinds: " << r.err;
    }
    const std::vector<double> dc_blinds = AnnualSums(out / "total.ill"),
                              five_blinds = AnnualSums(out / "total5.ill");
    ASSERT_EQ(dc_blinds.size(), 15u);
    ASSERT_EQ(five_blinds.size(), 15u);
    double sum_dc_blinds = 0, sum_five_blinds = 0;
    for (size_t i = 0; i < dc.size(); ++i)
        sum_dc_blinds += dc_blinds[i], sum_five_blinds += five_blinds[i];
    EXPECT_LT(sum_dc_blinds, 0.65 * sum_dc);
    EXPECT_LT(sum_five_blinds, 0.65 * sum_five);
    EXPECT_NEAR(sum_five_blinds / sum_dc_blinds, 1.19, 0.2) << sum_five_blinds / sum_dc_blinds;
    EXPECT_TRUE(fs::exists(out / "blinds.xml"));
}

// DAYSIM's method (examples/daysim: gen_dc, ds_illum, dcmetrics) on the same tiny office: each
// sensor's year of light as the daylight-coefficient run's within what the two sky models
// allow (DAYSIM's Perez sky at 145 patch centres, its sun shared between four of ~61 suns:
// 5-10 % lower here, about the noise of -ad 512 at the back), the same sensors, metrics written.
TEST(DaysimExample, TinyRunAgreesWithDaylightCoefficients) {
    const fs::path examples = DataDir() / ".." / ".." / "examples";
    TempDir tmp;
    const std::string settings =
        "make -s --no-print-directory BIN='" + BinDir().string() + "' NX=3 NY=5 AB=3 AD=512 ";
    CommandResult r = RunCommand(settings + "-C '" + (examples / "reference-office").string() +
                                     "' METHOD=dc OUT='" + (tmp.path() / "dc").string() + "'",
                                 tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    r = RunCommand(settings + "-C '" + (examples / "daysim").string() + "' OUT='" +
                       (tmp.path() / "daysim").string() + "'",
                   tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> dc = AnnualSums(tmp.path() / "dc" / "total.ill");
    std::vector<double> daysim(dc.size(), 0.0);
    std::istringstream ill(ReadFile(tmp.path() / "daysim" / "office.ill"));
    int hours = 0;
    for (std::string line; std::getline(ill, line); ++hours) {
        std::istringstream words(line);
        double month, day, hour, v;
        words >> month >> day >> hour;
        for (size_t i = 0; words >> v; ++i) {
            ASSERT_LT(i, daysim.size());
            daysim[i] += v;
        }
    }
    EXPECT_EQ(hours, 8760);
    double sum_dc = 0, sum_daysim = 0;
    for (size_t i = 0; i < dc.size(); ++i) {
        sum_dc += dc[i], sum_daysim += daysim[i];
        // 0.45: a back sensor's year moves by a third between seeds at -ad 512 in both runs,
        // partly together (the two draw the same keyed random numbers); over seeds 1-6 and two
        // versions of the core the ratios ranged over 0.74-1.39 (docs/benchmarks.md, 11-26).
        EXPECT_NEAR(daysim[i] / dc[i], 1, 0.45) << "sensor " << i;
    }
    EXPECT_NEAR(sum_daysim / sum_dc, 0.95, 0.08);
    const std::string metrics = ReadFile(tmp.path() / "daysim" / "metrics.txt");
    EXPECT_NE(metrics.find("office0            15"), std::string::npos) << metrics;
}

// The Debian package (cpack, CMakeLists.txt): made from this build, installed with dpkg (its
// dependencies are this machine's libraries), the tiny example run from its installed programs
// (/opt/dayflux/bin, the .cal files found beside them) gives the build tree's metrics, its
// RADIANCE names answer, and removing it leaves nothing. Only as root, with dpkg, where no dayflux
// is installed already.
TEST(ReferenceOfficeExample, InstalledPackageRunsIt) {
    if (geteuid() != 0) GTEST_SKIP() << "installing a package needs root";
    if (RunCommand("command -v dpkg cpack dpkg-shlibdeps", ".").status != 0)
        GTEST_SKIP() << "no dpkg, cpack or dpkg-shlibdeps";
    if (fs::exists("/opt/dayflux")) GTEST_SKIP() << "/opt/dayflux exists: not touched";
    const fs::path example = DataDir() / ".." / ".." / "examples" / "reference-office";
    TempDir tmp;
    CommandResult r = RunCommand("cd '" + (BinDir() / "..").string() + "' && cpack -B '" +
                                     tmp.path().string() + "' > /dev/null",
                                 tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    // Removed whatever happens once installing was tried (a failed dpkg -i leaves it unpacked).
    struct Purge {
        ~Purge() { RunCommand("dpkg --purge dayflux > /dev/null 2>&1", "/"); }
    } purge;
    r = RunCommand("dpkg -i dayflux_*.deb > /dev/null", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string common = "make -s --no-print-directory -C '" + example.string() +
                               "' NX=3 NY=5 AB=2 AD=64 NPROC=2 OUT='" + tmp.path().string();
    const CommandResult installed = RunCommand(common + "/installed' BIN=/opt/dayflux/bin", "/");
    const CommandResult version =
        RunCommand("/opt/dayflux/lib/dayflux/radiance/bin/rcontrib -version", "/");
    const CommandResult removed = RunCommand("dpkg -r dayflux > /dev/null", "/");
    EXPECT_EQ(removed.status, 0) << removed.err;
    EXPECT_FALSE(fs::exists("/opt/dayflux/bin"));
    ASSERT_EQ(installed.status, 0) << installed.err;
    EXPECT_EQ(version.out.rfind("RADIANCE 5.4a", 0), 0u) << version.out;
    r = RunCommand(common + "/built' BIN='" + BinDir().string() + "'", "/");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string csv = ReadFile(tmp.path() / "installed" / "metrics.csv");
    EXPECT_GT(csv.size(), 100u);
    EXPECT_EQ(csv, ReadFile(tmp.path() / "built" / "metrics.csv"));
}

}  // namespace
}  // namespace dayflux::test
