// The recipes people run (shared/spec/workflows.md sections 1-3: the LBNL tutorial's two-, three-
// and five-phase scripts, honeybee's annual daylight), run word for word through dayflux's folder
// of RADIANCE names on the tutorial room, against RADIANCE 5.4's outputs of the same command lines
// (test/data/recipes). Each is within RADIANCE's own noise: its relative RMS difference from the
// reference, over the entries and over the rows' sums, is at most 1.3 times that between two
// independent runs (the larger of RADIANCE against itself with -u+ and ours with two seeds, since
// RADIANCE's rfluxmtx samples its sender the same way every run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <tuple>

#include "matrix/matrices.h"
#include "test_util.h"

namespace dayflux::test {
namespace {

namespace fs = std::filesystem;

// Runs a command with RADIANCE's names first on PATH.
CommandResult RunAsRadiance(const std::string &command, const fs::path &dir) {
    return RunCommand("PATH='" + RadianceNames().string() + "':\"$PATH\"; " + command, dir);
}

// The tutorial room, its points and RADIANCE's octrees of it, with the recipes' folders.
void CopyRoom(const fs::path &to) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    fs::copy(room, to, fs::copy_options::recursive);
    fs::copy(DataDir() / "recipes" / "octrees", to / "octrees", fs::copy_options::recursive);
    fs::copy_file(DataDir() / "rcontrib" / "points.txt", to / "points.txt");
    for (const char *d :
         {"matrices/dc", "matrices/dcd", "matrices/vmtx", "matrices/dmtx", "matrices/vmtxd",
          "matrices/dmtxd", "matrices/tmtx", "skyVectors", "results/dc", "results/3ph"})
        fs::create_directories(to / d);
    fs::copy_file(DataDir() / "bsdf" / "clear.xml", to / "matrices" / "tmtx" / "clear.xml");
}

// sqrt(sum (a - b)^2) / sqrt(sum b^2) over every value, and over the rows' sums per component.
struct Differences {
    double entries = NAN, rowsums = NAN;
};
Differences Compare(const Matrix &a, const Matrix &b) {
    Differences d;
    if (a.rows != b.rows || a.cols != b.cols || a.ncomp != b.ncomp) return d;
    double e2 = 0, b2 = 0, r2 = 0, rb2 = 0;
    for (int r = 0; r < a.rows; ++r)
        for (int k = 0; k < a.ncomp; ++k) {
            double sa = 0, sb = 0;
            for (int c = 0; c < a.cols; ++c) {
                const double x = a.at(r, c, k), y = b.at(r, c, k);
                e2 += (x - y) * (x - y), b2 += y * y, sa += x, sb += y;
            }
            r2 += (sa - sb) * (sa - sb), rb2 += sb * sb;
        }
    d.entries = std::sqrt(e2 / b2);
    d.rowsums = std::sqrt(r2 / rb2);
    return d;
}

Matrix Reference(const std::string &name) {
    return LoadMatrix("!xzcat '" + (DataDir() / "recipes" / (name + ".fmx.xz")).string() + "'");
}

struct Recipe {
    const char *name;
    const char *command;  // as the recipe has it
    const char *output;
    const char *reference;  // test/data/recipes/<reference>.fmx.xz
    Differences noise;      // between two independent runs
};

class Recipes : public testing::TestWithParam<Recipe> {};

TEST_P(Recipes, AgreeWithRadianceWithinItsNoise) {
    const Recipe &recipe = GetParam();
    TempDir tmp;
    CopyRoom(tmp.path() / "room");
    const CommandResult r = RunAsRadiance(recipe.command, tmp.path() / "room");
    ASSERT_EQ(r.status, 0) << recipe.command << "\n" << r.err;
    const Matrix ours = LoadMatrix((tmp.path() / "room" / recipe.output).string());
    const Differences d = Compare(ours, Reference(recipe.reference));
    EXPECT_LE(d.entries, 1.3 * recipe.noise.entries) << recipe.command;
    EXPECT_LE(d.rowsums, 1.3 * recipe.noise.rowsums) << recipe.command;
}

INSTANTIATE_TEST_SUITE_P(
    Rfluxmtx, Recipes,
    testing::Values(
        // 1. Two-phase: daylight coefficients, their direct part on the black room (DDS).
        Recipe{"TwoPhaseDaylightCoefficients",
               "rfluxmtx -I+ -y 100 -lw 0.0001 -ab 5 -ad 10000 -n 16 - skyDomes/skyglow.rad -i "
               "octrees/roomDC.oct < points.txt > matrices/dc/illum.mtx",
               "matrices/dc/illum.mtx",
               "dc",
               {0.1065, 0.0160}},
        Recipe{"TwoPhaseDirectDaylightCoefficients",
               "rfluxmtx -I+ -y 100 -lw 0.0001 -ab 1 -ad 10000 -n 16 - skyDomes/skyglow.rad -i "
               "octrees/roomDCBlack.oct < points.txt > matrices/dcd/illum.mtx",
               "matrices/dcd/illum.mtx",
               "dcd",
               {0.0666, 0.0068}},
        // honeybee's annual daylight recipe (its matrix, before rmtxop).
        Recipe{"HoneybeeAnnualDaylight",
               "rfluxmtx -aa 0.0 -I -c 1 -faf -ab 2 -ad 5000 -lw 2e-05 -y 100 - "
               "skyDomes/skyglow.rad -i octrees/roomDC.oct < points.txt > results.fmx",
               "results.fmx",
               "hb",
               {0.1065, 0.0112}},
        // 2. Three-phase: view and daylight matrices.
        Recipe{"ThreePhaseView",
               "rfluxmtx -v -I+ -ab 4 -ad 5000 -lw 0.0002 -n 16 -y 100 - objects/GlazingVmtx.rad "
               "-i octrees/room3ph.oct < points.txt > matrices/vmtx/v.mtx",
               "matrices/vmtx/v.mtx",
               "v",
               {0.1880, 0.0220}},
        Recipe{"ThreePhaseDaylight",
               "rfluxmtx -v -ff -ab 4 -ad 1000 -lw 0.001 -c 1000 -n 16 objects/GlazingVmtx.rad "
               "skyDomes/skyglow.rad -i octrees/room3ph.oct > matrices/dmtx/daylight.dmx",
               "matrices/dmtx/daylight.dmx",
               "d",
               {0.0295, 0.0121}},
        // 3. Five-phase: the direct-only view and daylight matrices on the black room.
        Recipe{"FivePhaseDirectView",
               "rfluxmtx -v -I+ -ab 1 -ad 5000 -lw 0.0002 -n 16 -y 100 - objects/GlazingVmtx.rad "
               "-i octrees/room3phDirect.oct < points.txt > matrices/vmtxd/v.mtx",
               "matrices/vmtxd/v.mtx",
               "vd",
               {0.1021, 0.0090}},
        Recipe{"FivePhaseDirectDaylight",
               "rfluxmtx -v -ff -ab 0 -ad 1000 -lw 0.001 -c 1000 -n 16 objects/GlazingVmtx.rad "
               "skyDomes/skyglow.rad -i octrees/room3phDirect.oct > matrices/dmtxd/daylight.dmx",
               "matrices/dmtxd/daylight.dmx",
               "dd",
               {0.0274, 0.0140}}),
    [](const testing::TestParamInfo<Recipe> &info) { return std::string(info.param.name); });

// The tutorial's view-matrix pictures (its line with 16 x 9 pixels for 400 x 400): vwrays' rays
// (RADIANCE's, test/data/recipes/south.rays, from `vwrays -vf views/south.vf -x 16 -y 9 -pj 0.7
// -c 9 -ff`), and its `vwrays -d` as it prints (-x 16 -y 9 -ld-), give a picture per Klems bin
// whose pixels agree with RADIANCE's (vpics: a row per pixel, a column per bin) within its noise:
// two runs of either differ by 0.0063 over the entries and 0.0044 over the pixels' sums.
TEST(Recipes, ViewMatrixPicturesAgreeWithRadianceWithinItsNoise) {
    TempDir tmp;
    const fs::path room = tmp.path() / "room";
    CopyRoom(room);
    fs::create_directories(room / "matrices" / "vmtx" / "hdr");
    fs::copy_file(DataDir() / "recipes" / "south.rays", room / "south.rays");
    const std::string command =
        "rfluxmtx -v -ffc -x 16 -y 9 -ld- -o matrices/vmtx/hdr/south%03d.hdr -ab 4 -ad 1000 -lw "
        "1e-4 -c 9 -n 16 - objects/GlazingVmtx.rad -i octrees/room3ph.oct < south.rays";
    const CommandResult r = RunAsRadiance(command, room);
    ASSERT_EQ(r.status, 0) << r.err;
    const Matrix ref = Reference("vpics");
    ASSERT_EQ(ref.rows, 16 * 9);
    ASSERT_EQ(ref.cols, 145);
    Matrix ours(ref.rows, ref.cols, 3);
    for (int bin = 0; bin < ref.cols; ++bin) {
        char name[64];
        std::snprintf(name, sizeof name, "matrices/vmtx/hdr/south%03d.hdr", bin);
        const Matrix picture = LoadMatrix((room / name).string());
        ASSERT_EQ(picture.rows, 9);
        ASSERT_EQ(picture.cols, 16);
        for (int pixel = 0; pixel < ref.rows; ++pixel)
            for (int k = 0; k < 3; ++k) ours.at(pixel, bin, k) = picture.data[3 * pixel + k];
    }
    const Differences d = Compare(ours, ref);
    EXPECT_LE(d.entries, 1.3 * 0.0063);
    EXPECT_LE(d.rowsums, 1.3 * 0.0044);
}

// The annual recipe from the scene files on, word for word, with dayflux alone on PATH (no
// RADIANCE anywhere): the octrees, the matrices, the sky and a year's illuminance from the
// two-phase DC and from V T D, against the same steps on RADIANCE's matrices (relative RMS
// difference of the hourly illuminances at most 1.3 times that between two independent runs:
// 0.038 and 0.045).
TEST(Recipes, AnnualIlluminanceAgreesWithRadianceWithinItsNoise) {
    TempDir tmp;
    const fs::path room = tmp.path() / "room";
    CopyRoom(room);
    fs::remove_all(room / "octrees");  // RADIANCE's: made again here
    fs::create_directories(room / "octrees");
    fs::copy_file(DataDir() / "sky" / "nyc.wea", room / "NYC.wea");
    const char *steps[] = {
        "oconv materials.rad room.rad objects/Glazing.rad > octrees/roomDC.oct",
        "oconv -f materials.rad room.rad > octrees/room3ph.oct",
        "rfluxmtx -I+ -y 100 -lw 0.0001 -ab 5 -ad 10000 -n 16 - skyDomes/skyglow.rad -i "
        "octrees/roomDC.oct < points.txt > matrices/dc/illum.mtx",
        "rfluxmtx -v -I+ -ab 4 -ad 5000 -lw 0.0002 -n 16 -y 100 - objects/GlazingVmtx.rad -i "
        "octrees/room3ph.oct < points.txt > matrices/vmtx/v.mtx",
        "rfluxmtx -v -ff -ab 4 -ad 1000 -lw 0.001 -c 1000 -n 16 objects/GlazingVmtx.rad "
        "skyDomes/skyglow.rad -i octrees/room3ph.oct > matrices/dmtx/daylight.dmx",
        "gendaymtx -m 1 NYC.wea > skyVectors/NYC.smx",
        "dctimestep matrices/dc/illum.mtx skyVectors/NYC.smx | rmtxop -fa -t -c 47.4 119.9 11.6 "
        "- > results/dc/annualR.ill",
        "dctimestep matrices/vmtx/v.mtx matrices/tmtx/clear.xml matrices/dmtx/daylight.dmx "
        "skyVectors/NYC.smx | rmtxop -fa -t -c 47.4 119.9 11.6 - > results/3ph/3phAnnual.ill",
        // The same steps on RADIANCE's matrices.
        "dctimestep '!xzcat ref/dc.fmx.xz' skyVectors/NYC.smx | rmtxop -fa -t -c 47.4 119.9 "
        "11.6 - > ref_dc.ill",
        "dctimestep '!xzcat ref/v.fmx.xz' matrices/tmtx/clear.xml '!xzcat ref/d.fmx.xz' "
        "skyVectors/NYC.smx | rmtxop -fa -t -c 47.4 119.9 11.6 - > ref_3ph.ill"};
    fs::copy(DataDir() / "recipes", room / "ref", fs::copy_options::recursive);
    for (const char *step : steps) {
        const CommandResult r = RunWithDayfluxAlone(step, room);
        ASSERT_EQ(r.status, 0) << step << "\n" << r.err;
    }
    const Matrix dc = LoadMatrix((room / "results/dc/annualR.ill").string());
    const Matrix three = LoadMatrix((room / "results/3ph/3phAnnual.ill").string());
    ASSERT_EQ(dc.cols, 100);
    ASSERT_GT(dc.rows, 10);  // one row per hour of the weather file
    EXPECT_LE(Compare(dc, LoadMatrix((room / "ref_dc.ill").string())).entries, 1.3 * 0.038);
    EXPECT_LE(Compare(three, LoadMatrix((room / "ref_3ph.ill").string())).entries, 1.3 * 0.045);
}

// The folder of RADIANCE names runs ours under them, hands what dayflux lacks to RADIANCE's
// program of that name further along PATH (saying so), and otherwise says what is missing.
TEST(RadianceNames, RunOursAndReportTheRest) {
    TempDir tmp;
    CommandResult r = RunAsRadiance("rcontrib -devices >/dev/null && rfluxmtx 2>&1", tmp.path());
    EXPECT_NE(r.out.find("rfluxmtx: Usage: rfluxmtx"), std::string::npos) << r.out << r.err;
    r = RunAsRadiance("rpict view.oct", tmp.path());
    EXPECT_EQ(r.status, 127);
    EXPECT_NE(r.err.find("rpict: not implemented by dayflux"), std::string::npos) << r.err;
    fs::create_directories(tmp.path() / "radiance");
    WriteFile(tmp.path() / "radiance" / "rpict", "#!/bin/sh\necho RADIANCE rpict \"$@\"\n");
    fs::permissions(tmp.path() / "radiance" / "rpict", fs::perms::owner_all);
    r = RunAsRadiance("PATH=\"$PATH:" + (tmp.path() / "radiance").string() + "\" rpict a.oct",
                      tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "RADIANCE rpict a.oct\n");
    EXPECT_NE(r.err.find("rpict: not in dayflux; running RADIANCE's"), std::string::npos) << r.err;
}

// -version on every program, ours under their own names and RADIANCE's, and on the names dayflux
// lacks: a first line in RADIANCE's form, as honeybee-radiance parses it (its installation probe:
// the YYYY-MM-DD date at least 2020-09-03, the version in the last brackets, 5.4), naming dayflux
// and the program, and exit status 0.
TEST(RadianceNames, EveryProgramAnswersVersion) {
    std::vector<fs::path> programs;
    for (const fs::path &dir : {BinDir(), RadianceNames()})
        for (const auto &e : fs::directory_iterator(dir))
            if (e.path().filename() != "radiance-missing.sh") programs.push_back(e.path());
    ASSERT_GT(programs.size(), 40u);
    const std::regex date(R"((\d*)-(\d*)-(\d*))");
    for (const fs::path &program : programs) {
        SCOPED_TRACE(program.string());
        const CommandResult r = RunCommand("'" + program.string() + "' -version", BinDir());
        EXPECT_EQ(r.status, 0) << r.err;
        const std::string line = r.out.substr(0, r.out.find('\n'));
        EXPECT_EQ(line.rfind("RADIANCE 5.4a ", 0), 0u) << line;
        EXPECT_NE(line.find("dayflux"), std::string::npos) << line;
        EXPECT_NE(line.find(program.filename().string()), std::string::npos) << line;
        std::smatch m;
        ASSERT_TRUE(std::regex_search(line, m, date)) << line;
        EXPECT_GE(std::make_tuple(std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3])),
                  std::make_tuple(2020, 9, 3));
        const std::string bracketed = line.substr(line.rfind('(') + 1);
        EXPECT_EQ(bracketed.substr(0, bracketed.find(')')), "5.4") << line;
    }
}

}  // namespace
}  // namespace dayflux::test
