// gendaymtx and epw2wea against RADIANCE 5.4 (test/data/sky/make_references.sh made the
// references), RADIANCE's own regression test, and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "matrix/reader.h"
#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;

namespace {

fs::path SkyData() { return DataDir() / "sky"; }

struct Loaded {
    int rows = 0, cols = 0;
    std::vector<double> v;
};

Loaded Load(const std::string &spec) {
    MatrixReader r(spec);
    Loaded m;
    m.cols = r.Cols();
    std::vector<double> row(static_cast<size_t>(r.Cols()) * r.Comps());
    while (r.ReadRow(row.data())) m.v.insert(m.v.end(), row.begin(), row.end()), ++m.rows;
    return m;
}

// The criterion: every entry within 1e-5 relative of RADIANCE's, entries below 1e-3 of
// their column's maximum excepted.
void ExpectSkyMatrixEqual(const std::string &ref_spec, const std::string &test_spec) {
    Loaded a = Load(ref_spec), b = Load(test_spec);
    ASSERT_EQ(a.rows, b.rows) << test_spec;
    ASSERT_EQ(a.cols, b.cols) << test_spec;
    std::vector<double> colmax(a.cols, 0);
    for (int r = 0; r < a.rows; ++r)
        for (int c = 0; c < a.cols; ++c)
            for (int k = 0; k < 3; ++k)
                colmax[c] = std::max(colmax[c], std::fabs(a.v[(r * a.cols + c) * 3 + k]));
    int bad = 0;
    for (int r = 0; r < a.rows; ++r)
        for (int c = 0; c < a.cols; ++c)
            for (int k = 0; k < 3; ++k) {
                const double x = a.v[(r * a.cols + c) * 3 + k], y = b.v[(r * a.cols + c) * 3 + k];
                if (std::fabs(x) < 1e-3 * colmax[c]) continue;
                if (std::fabs(x - y) > 1e-5 * std::fabs(x) && bad++ < 5)
                    ADD_FAILURE() << test_spec << " row " << r << " col " << c << ": " << y
                                  << " vs RADIANCE " << x;
            }
    EXPECT_EQ(bad, 0) << test_spec;
}

struct Case {
    std::string args, reference, input;
};

std::vector<Case> Cases() {
    std::vector<Case> cases;
    for (std::string site : {"denver", "nyc", "frads"}) {
        const std::string w = site + ".wea";
        cases.push_back({"-m 1 -of " + w, site + "_m1.fmx", w});
        cases.push_back({"-m 2 -of " + w, site + "_m2.fmx", w});
        cases.push_back({"-m 2 -d -of " + w, site + "_m2_d.fmx", w});
        cases.push_back({"-m 2 -s -of " + w, site + "_m2_s.fmx", w});
        cases.push_back({"-m 6 -5 0.533 -d -of " + w, site + "_m6_5ph.fmx", w});
        cases.push_back({"-m 1 -O1 -of " + w, site + "_m1_O1.fmx", w});
        cases.push_back({"-m 1 -r 30 -g .1 .2 .3 -c 1 .9 .8 -of " + w, site + "_m1_r_g_c.fmx", w});
    }
    cases.push_back({"-m 4 -of denver.wea", "denver_m4.fmx", "denver.wea"});
    cases.push_back({"-m 6 -of denver.wea", "denver_m6.fmx", "denver.wea"});
    cases.push_back({"-m 1 -of frads_u2.wea", "frads_u2_m1.fmx", "frads_u2.wea"});
    cases.push_back({"-m 1 -of frads_u3.wea", "frads_u3_m1.fmx", "frads_u3.wea"});
    cases.push_back({"-m 1 -of leap.wea", "leap_m1.fmx", "leap.wea"});
    return cases;
}

}  // namespace

class GendaymtxReference : public testing::TestWithParam<Case> {};

TEST_P(GendaymtxReference, MatchesRadiance) {
    const Case &c = GetParam();
    TempDir tmp;
    fs::create_symlink(SkyData() / c.input, tmp.path() / c.input);
    CommandResult r = RunCommand("gendaymtx " + c.args + " > out.fmx", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    ExpectSkyMatrixEqual("!xzcat '" + (SkyData() / (c.reference + ".xz")).string() + "'",
                         (tmp.path() / "out.fmx").string());
}

INSTANTIATE_TEST_SUITE_P(Skies, GendaymtxReference, testing::ValuesIn(Cases()),
                         [](const auto &info) {
                             std::string n =
                                 info.param.reference.substr(0, info.param.reference.find('.'));
                             for (char &ch : n)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });

TEST(Gendaymtx, SunDescriptionsMatchRadiance) {
    for (std::string site : {"denver", "nyc", "frads"}) {
        TempDir tmp;
        fs::create_symlink(SkyData() / (site + ".wea"), tmp.path() / "w.wea");
        CommandResult r =
            RunCommand("gendaymtx -D suns.rad -M suns.mod -m 1 -of w.wea > m.fmx", tmp.path());
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(ReadFile(tmp.path() / "suns.rad"), ReadFile(SkyData() / (site + "_suns.rad")))
            << site;
        EXPECT_EQ(ReadFile(tmp.path() / "suns.mod"), ReadFile(SkyData() / (site + "_suns.mod")))
            << site;
        ExpectSkyMatrixEqual("!xzcat '" + (SkyData() / (site + "_m1_D.fmx.xz")).string() + "'",
                             (tmp.path() / "m.fmx").string());
        r = RunCommand("gendaymtx -D - w.wea", tmp.path());
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(r.out, ReadFile(SkyData() / (site + "_suns_stdout.rad"))) << site;
    }
}

// RADIANCE's own regression test for gendaymtx (test/gen in RADIANCE's sources), to the character.
TEST(Gendaymtx, RadianceRegressionTest) {
    TempDir tmp;
    fs::create_symlink(SkyData() / "radiance_gen/test.wea", tmp.path() / "test.wea");
    CommandResult r =
        RunCommand("gendaymtx -r 90 -m 1 -g .3 .2 .1 -c .9 .9 1.2 test.wea", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, ReadFile(SkyData() / "radiance_gen/test.smx"));
}

TEST(Epw2wea, MatchesRadianceAndFeedsGendaymtx) {
    TempDir tmp;
    fs::create_symlink(SkyData() / "epw/NLD_Amsterdam.062400_IWEC.epw", tmp.path() / "a.epw");
    CommandResult r = RunCommand("epw2wea a.epw a.wea", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(ReadFile(tmp.path() / "a.wea"), ReadFile(SkyData() / "epw/amsterdam.wea"));
    EXPECT_EQ(r.out, ReadFile(SkyData() / "epw/amsterdam_epw2wea_stdout.txt"));
    // Without an output file the .wea goes to stdout; gendaymtx also reads the EPW directly.
    EXPECT_EQ(RunCommand("epw2wea a.epw", tmp.path()).out,
              ReadFile(SkyData() / "epw/amsterdam.wea"));
    CommandResult direct = RunCommand("gendaymtx -h -m 2 -of a.epw", tmp.path());
    CommandResult piped = RunCommand("epw2wea a.epw | gendaymtx -h -m 2 -of", tmp.path());
    ASSERT_EQ(direct.status + piped.status, 0) << direct.err << piped.err;
    EXPECT_EQ(direct.out.size(), 578u * 8760 * 12);
    EXPECT_TRUE(direct.out == piped.out);
}

class BadWeather : public testing::Test {
  protected:
    std::string Error(const std::string &wea, const std::string &args = "") {
        WriteFile(tmp_.path() / "t.wea", wea);
        CommandResult r = RunCommand("gendaymtx " + args + " t.wea > /dev/null", tmp_.path());
        EXPECT_NE(r.status, 0);
        return r.err;
    }
    TempDir tmp_;
    const std::string head_ =
        "place X\nlatitude 40\nlongitude 105\ntime_zone 105\nsite_elevation "
        "1600\nweather_data_file_units 1\n";
};

TEST_F(BadWeather, MessagesNameFileLineAndProblem) {
    EXPECT_EQ(Error(head_ + "1 1 12.5 500 100\n1 1 13.5 5OO 100\n"),
              "gendaymtx: t.wea:8: non-numeric field in '1 1 13.5 5OO 100'\n");
    EXPECT_EQ(Error(head_ + "13 1 12.5 500 100\n"), "gendaymtx: t.wea:7: month 13 is not 1..12\n");
    EXPECT_EQ(Error(head_ + "2 30 12.5 500 100\n"),
              "gendaymtx: t.wea:7: day 30 does not exist in month 2\n");
    EXPECT_EQ(Error(head_ + "1 1 12.5 -5 100\n"),
              "gendaymtx: t.wea:7: negative or non-numeric radiation value\n");
    EXPECT_EQ(
        Error(head_ + "1 1 12.5 500\n"),
        "gendaymtx: t.wea:7: expected 'month day hour direct diffuse', found '1 1 12.5 500'\n");
    EXPECT_EQ(Error("place X\nlongitude 105\n"),
              "gendaymtx: t.wea:2: expected 'latitude <degrees north>' in the header, found "
              "'longitude 105'\n");
    EXPECT_EQ(Error("place X\nlatitude 140\n"),
              "gendaymtx: t.wea:2: latitude 140 is outside -90..90\n");
    EXPECT_EQ(Error(head_), "gendaymtx: t.wea: no valid time steps on input\n");
    std::string units = head_;
    units.replace(units.find("units 1"), 7, "units 4");
    EXPECT_EQ(Error(units),
              "gendaymtx: t.wea:6: weather_data_file_units must be 1, 2 or 3, not 4\n");
    EXPECT_NE(Error(head_ + "1 1 12.5 500 100\n", "-5 0").find("missing solar disk size"),
              std::string::npos);
    EXPECT_NE(Error(head_ + "1 1 12.5 500 100\n", "-q").find("Usage:"), std::string::npos);
    CommandResult r = RunCommand("gendaymtx nosuch.wea", tmp_.path());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("cannot open file 'nosuch.wea'"), std::string::npos);
}

TEST_F(BadWeather, KeepsRadiancesWarning) {
    // Direct sun while the sun is below the horizon.
    WriteFile(tmp_.path() / "t.wea", head_ + "1 1 2.5 300 10\n1 1 12.5 500 100\n");
    CommandResult r = RunCommand("gendaymtx t.wea > /dev/null", tmp_.path());
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.err, "gendaymtx: warning - unusually bright at 2.5 on 1-1\n");
}

TEST_F(BadWeather, EpwMissingValues) {
    std::string epw = ReadFile(SkyData() / "epw/NLD_Amsterdam.062400_IWEC.epw");
    // Line 9 is the first data line; replace its direct normal irradiance (field 15) by 9999.
    size_t line9 = 0;
    for (int i = 0; i < 8; ++i) line9 = epw.find('\n', line9) + 1;
    size_t field = line9;
    for (int i = 0; i < 14; ++i) field = epw.find(',', field) + 1;
    epw.replace(field, epw.find(',', field) - field, "9999");
    WriteFile(tmp_.path() / "m.epw", epw);
    CommandResult r = RunCommand("epw2wea m.epw", tmp_.path());
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(r.err, "epw2wea: m.epw:9: direct normal irradiance (field 15) is missing (9999)\n");
}

}  // namespace dayflux::test
