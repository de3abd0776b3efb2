// dcmetrics end to end: layouts (sensors or steps as rows), RGB irradiance, weather calendars
// with gendaymtx -u, grids and area weights, CSV/JSON output, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;
namespace {

// An ascii matrix of sensors x steps (or its transpose) with value(sensor, step).
template <class F>
std::string AsciiMatrix(int sensors, int steps, int ncomp, bool steps_are_rows, F value) {
    std::ostringstream s;
    s.precision(17);
    const int rows = steps_are_rows ? steps : sensors, cols = steps_are_rows ? sensors : steps;
    s << "#?RADIANCE\nNROWS=" << rows << "\nNCOLS=" << cols << "\nNCOMP=" << ncomp
      << "\nFORMAT=ascii\n\n";
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            const double v = steps_are_rows ? value(c, r) : value(r, c);
            for (int k = 0; k < ncomp; ++k) s << v << (k + 1 < ncomp ? " " : "\t");
        }
        s << "\n";
    }
    return s.str();
}

class DcmetricsTest : public ::testing::Test {
  protected:
    // Sensor s: 400 + s lux before noon and 50 lux after; sensor 0 alone has 2000 lux of
    // direct sun, at 08:30 every day.
    static double Total(int s, int step) { return (step % 24) < 12 ? 400. + s : 50.; }
    static double Direct(int s, int step) { return s == 0 && step % 24 == 8 ? 2000. : 0.; }
    TempDir tmp_;

    CommandResult Run(const std::string &cmd) { return RunCommand(cmd, tmp_.path()); }
};

TEST_F(DcmetricsTest, MetricsCsvJsonAndLayouts) {
    WriteFile(tmp_.path() / "total.mtx", AsciiMatrix(3, 8760, 1, false, Total));
    WriteFile(tmp_.path() / "direct.mtx", AsciiMatrix(3, 8760, 1, false, Direct));
    CommandResult r = Run("dcmetrics -g west 1 -g east 2 -o m total.mtx direct.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    // Occupied 08:30..17:30: 4 of 10 hours are mornings at 400+ lux, so DA is 40 % everywhere,
    // sDA 0; ASE: sensor 0 has 365 direct hours above 1000 lux (> 250), so ASE is 100 % of
    // "west" and 0 % of "east".
    EXPECT_NE(r.out.find("3650 occupied hours"), std::string::npos) << r.out;
    const std::string csv = ReadFile(tmp_.path() / "m.csv");
    EXPECT_NE(csv.find("grid,sensor,area,DA,cDA,UDI_lower,UDI,UDI_upper,ASE_hours\n"
                       "west,0,1.000000,40.0000,"),
              std::string::npos)
        << csv;
    EXPECT_NE(csv.find(",365.00\n"), std::string::npos) << csv;
    const std::string json = ReadFile(tmp_.path() / "m.json");
    EXPECT_NE(json.find("\"name\": \"west\", \"sensors\": 1, \"area\": 1.000000, \"sDA\": "
                        "0.0000, \"ASE\": 100.0000"),
              std::string::npos)
        << json;
    EXPECT_NE(json.find("\"name\": \"east\", \"sensors\": 2, \"area\": 2.000000, \"sDA\": "
                        "0.0000, \"ASE\": 0.0000"),
              std::string::npos)
        << json;
    // cDA: 4 hours at 1 and 6 hours at 50/300.
    EXPECT_NE(json.find("\"mean_cDA\": " + std::to_string(40. + 60. / 6.).substr(0, 7)),
              std::string::npos)
        << json;

    // From a pipe: each input is read once.
    CommandResult piped =
        Run("cat total.mtx | dcmetrics -g west 1 -g east 2 -o p - '!cat direct.mtx'");
    ASSERT_EQ(piped.status, 0) << piped.err;
    EXPECT_EQ(ReadFile(tmp_.path() / "p.csv"), csv);

    // The same as RGB irradiance with hours as rows (rmtxop -t): grey E / 178.9 in each channel,
    // since 47.4 + 119.9 + 11.6 = 178.9.
    WriteFile(tmp_.path() / "rgb.mtx",
              AsciiMatrix(3, 8760, 3, true, [](int s, int t) { return Total(s, t) / 178.9; }));
    CommandResult t = Run("dcmetrics -t -g west 1 -g east 2 -o t rgb.mtx");
    ASSERT_EQ(t.status, 0) << t.err;
    const std::string tcsv = ReadFile(tmp_.path() / "t.csv");
    // Equal but for the ASE column, which needs the direct-sun matrix.
    const auto second_line_without_ase = [](const std::string &text) {
        const size_t start = text.find('\n') + 1;
        return text.substr(start, text.rfind(',', text.find('\n', start)) - start);
    };
    EXPECT_EQ(second_line_without_ase(tcsv), second_line_without_ase(csv));
}

// Negative illuminance (a five-phase sum's noise) is no light: the metrics are those of zeros,
// not of an average pulled down, and one warning says how many there were and the lowest.
TEST_F(DcmetricsTest, NegativeIlluminanceCountsAsNone) {
    WriteFile(tmp_.path() / "total.mtx", AsciiMatrix(3, 8760, 1, false, Total));
    // Afternoons at -5000 lux instead of 50: a mean would fall below 300 lux.
    WriteFile(tmp_.path() / "negative.mtx", AsciiMatrix(3, 8760, 1, false, [](int s, int t) {
                  return (t % 24) < 12 ? 400. + s : (s == 1 && t == 13 ? -9000. : -5000.);
              }));
    WriteFile(tmp_.path() / "zero.mtx", AsciiMatrix(3, 8760, 1, false, [](int s, int t) {
                  return (t % 24) < 12 ? 400. + s : 0.;
              }));
    const CommandResult negative = Run("dcmetrics -o n negative.mtx");
    ASSERT_EQ(negative.status, 0) << negative.err;
    EXPECT_NE(negative.err.find("negative.mtx: 13140 negative illuminance value(s) taken as 0 "
                                "(the lowest, -9000 lux, at row 2 column 14)"),
              std::string::npos)
        << negative.err;
    ASSERT_EQ(Run("dcmetrics -o z zero.mtx").status, 0);
    EXPECT_EQ(ReadFile(tmp_.path() / "n.csv"), ReadFile(tmp_.path() / "z.csv"));
}

TEST_F(DcmetricsTest, WeatherCalendarWithSunUpSteps) {
    // A leap-year .wea from two days: with -u the matrix holds only the sun-up steps, and the
    // occupied steps left out still count in the denominator.
    std::string wea =
        "place test\nlatitude 42.37\nlongitude 71.03\ntime_zone 75\n"
        "site_elevation 5\nweather_data_file_units 1\n";
    for (int d : {28, 29})
        for (int h = 0; h < 24; ++h)
            wea += "2 " + std::to_string(d) + " " + std::to_string(h) + ".5 100 100\n";
    WriteFile(tmp_.path() / "two.wea", wea);
    // Boston in late February: 11 steps a day have the sun up, 06:30 to 16:30 (RADIANCE 5.4's
    // gendaymtx -u writes 22 columns for this file). Column j holds 190 + 50 (j % 11) lux, so with
    // 08:00-18:00 occupancy each day has 08:30 at 290 lux, 09:30-16:30 at 340-640 lux, and
    // 17:30 (sun down, not in the matrix) dark: DA 80 %, cDA (8 + 290/300) / 10, UDI 90 %.
    WriteFile(tmp_.path() / "up.mtx",
              AsciiMatrix(1, 22, 1, false, [](int, int j) { return 190. + 50. * (j % 11); }));
    CommandResult r = Run("dcmetrics -w two.wea -u -occ 8 18 -o m up.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("20 occupied hours"), std::string::npos) << r.out;
    EXPECT_NE(ReadFile(tmp_.path() / "m.csv")
                  .find("grid,0,1.000000,80.0000,89.6667,10.0000,90.0000,0.0000,\n"),
              std::string::npos)
        << ReadFile(tmp_.path() / "m.csv");
    // Sub-hourly weather: 96 quarter-hour steps, each counting a quarter of an hour.
    std::string quarter =
        "place test\nlatitude 42.37\nlongitude 71.03\ntime_zone 75\n"
        "site_elevation 5\nweather_data_file_units 1\n";
    for (int q = 0; q < 96; ++q)
        quarter += "3 1 " + std::to_string((q + 0.5) * 0.25) + " 100 100\n";
    WriteFile(tmp_.path() / "quarter.wea", quarter);
    WriteFile(tmp_.path() / "q.mtx", AsciiMatrix(1, 96, 1, false, [](int, int j) {
                  return j < 48 ? 500. : 50.;  // bright until noon
              }));
    CommandResult qr = Run("dcmetrics -w quarter.wea -o q q.mtx");
    ASSERT_EQ(qr.status, 0) << qr.err;
    EXPECT_NE(qr.out.find("10 occupied hours"), std::string::npos) << qr.out;
    EXPECT_NE(ReadFile(tmp_.path() / "q.csv").find("grid,0,1.000000,40.0000,"), std::string::npos)
        << ReadFile(tmp_.path() / "q.csv");
    // Without -u the counts disagree, and the message says why.
    CommandResult bad = Run("dcmetrics -w two.wea up.mtx");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.err.find("22 time steps, but two.wea gives 48 (22 with the sun up"),
              std::string::npos)
        << bad.err;
}

TEST_F(DcmetricsTest, BadInput) {
    WriteFile(tmp_.path() / "total.mtx", AsciiMatrix(2, 8760, 1, false, Total));
    WriteFile(tmp_.path() / "small.mtx", AsciiMatrix(2, 100, 1, false, Total));
    WriteFile(tmp_.path() / "direct3.mtx", AsciiMatrix(3, 8760, 1, false, Direct));
    std::string ragged = AsciiMatrix(2, 8760, 1, false, Total);
    ragged.insert(ragged.find("\n\n") + 2, "7 ");  // one value too many
    WriteFile(tmp_.path() / "ragged.mtx", ragged);
    std::string shortm = AsciiMatrix(2, 8760, 1, false, Total);
    shortm.resize(shortm.size() - 20);
    WriteFile(tmp_.path() / "short.mtx", shortm);
    WriteFile(tmp_.path() / "sched.txt", "1\n0\n");
    WriteFile(tmp_.path() / "areas.txt", "1 -2\n");
    WriteFile(tmp_.path() / "inf.txt", "inf 1\n");
    struct Case {
        std::string cmd, message;
    };
    const Case cases[] = {
        {"dcmetrics -o m small.mtx", "small.mtx: 100 time steps is not an hourly year"},
        {"dcmetrics -o m total.mtx direct3.mtx",
         "direct3.mtx: 3 sensors x 8760 time steps, but the illuminance matrix has 2 x 8760"},
        {"dcmetrics -o m ragged.mtx", "more than the header's size"},
        {"dcmetrics short.mtx", "short.mtx"},
        {"dcmetrics -o m -s sched.txt total.mtx",
         "sched.txt: 2 occupancy values for 8760 time steps"},
        {"dcmetrics -g a 0 total.mtx", "-g a: '0' is not a positive sensor count"},
        {"dcmetrics -o m -g a,b 2 total.mtx", "a grid name must be non-empty, without commas"},
        {"dcmetrics -o m -a inf.txt total.mtx", "inf.txt:1: sensor area 'inf' is not a positive"},
        {"dcmetrics -g a 1 total.mtx", "the grids (-g) hold 1 sensors, but total.mtx has 2"},
        {"dcmetrics -a areas.txt total.mtx", "areas.txt:1: sensor area '-2' is not a positive"},
        {"dcmetrics missing.mtx", "missing.mtx"},
        {"dcmetrics -occ 18 8 total.mtx", "-occ: the start must come before the end"},
        {"dcmetrics -udi 3000 x total.mtx", "'x' is not a number"},
    };
    for (const Case &c : cases) {
        CommandResult r = Run(c.cmd);
        EXPECT_EQ(r.status, 1) << c.cmd;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.cmd << ": " << r.err;
        EXPECT_FALSE(fs::exists(tmp_.path() / "m.csv")) << c.cmd;
    }
}

// -e: sensors' errors carried to DA and sDA by resampling. Sensor 0 (350 lux, 10 % error) falls
// below 300 lux when scaled by less than 0.857 (z < -1.43: about 8 % of resamples), so its DA is
// 100 or 0; sensor 1 (350 lux, no error) and sensor 2 (1000 lux, 10 %) never change.
TEST_F(DcmetricsTest, SensorErrorsGiveTheUncertaintyOfDaAndSda) {
    const auto lux = [](int s, int) { return s == 2 ? 1000. : 350.; };
    WriteFile(tmp_.path() / "total.mtx", AsciiMatrix(3, 8760, 1, false, lux));
    WriteFile(tmp_.path() / "errors.txt",
              "# sensor samples error\n0 4096 0.1\n1 4096 0\n2 512 0.1\n");
    const CommandResult r = Run("dcmetrics -e errors.txt -o m total.mtx");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("# grid: sDA 100.0% +- "), std::string::npos) << r.out;
    std::istringstream csv(ReadFile(tmp_.path() / "m.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "grid,sensor,area,DA,cDA,UDI_lower,UDI,UDI_upper,ASE_hours,DA_sd");
    std::vector<double> sd;
    while (std::getline(csv, line)) sd.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    ASSERT_EQ(sd.size(), 3u);
    EXPECT_GT(sd[0], 10);  // 100 sqrt(p (1 - p)), p about 0.08: 27
    EXPECT_LT(sd[0], 45);
    EXPECT_EQ(sd[1], 0);
    EXPECT_EQ(sd[2], 0);
    const std::string json = ReadFile(tmp_.path() / "m.json");
    const size_t at = json.find("\"sDA_sd\": ");
    ASSERT_NE(at, std::string::npos);
    const double sda_sd = std::stod(json.substr(at + 10));
    EXPECT_GT(sda_sd, 3);  // 33 sqrt(p (1 - p)): 9
    EXPECT_LT(sda_sd, 16);
    // The same numbers every run (a fixed seed).
    EXPECT_EQ(Run("dcmetrics -e errors.txt total.mtx").out, r.out);
    // Bad error files: a sensor out of order, a word too many, too few sensors.
    for (const char *bad : {"1 5 0.1\n", "0 5 0.1 x\n", "0 5 0.1\n1 5 0.2\n"}) {
        WriteFile(tmp_.path() / "bad.txt", bad);
        const CommandResult b = Run("dcmetrics -e bad.txt total.mtx");
        EXPECT_EQ(b.status, 1) << bad;
        EXPECT_NE(b.err.find("bad.txt"), std::string::npos) << b.err;
    }
}

TEST_F(DcmetricsTest, FcplanDrawsMetricsAndRejectsMismatches) {
    WriteFile(tmp_.path() / "total.mtx", AsciiMatrix(3, 8760, 1, false, Total));
    WriteFile(tmp_.path() / "s.pts", "0.5 0.5 1 0 0 1\n1.5 0.5 1 0 0 1\n2.5 0.5 1 0 0 1\n");
    WriteFile(tmp_.path() / "two.pts", "0.5 0.5 1 0 0 1\n1.5 0.5 1 0 0 1\n");
    ASSERT_EQ(Run("dcmetrics -o m total.mtx").status, 0);
    CommandResult r = Run("fcplan -i s.pts -c DA -s 100 -w 50 -o da.png -hdr da.hdr m.csv");
    ASSERT_EQ(r.status, 0) << r.err;
    // Metrics go into the HDR as they are: DA is 40 % everywhere.
    // First pixel of a picture, through rmtxop (RGBE keeps about 1 % of precision).
    const auto first_pixel = [&](const std::string &pic) {
        CommandResult p = Run("rmtxop -fa " + pic);
        EXPECT_EQ(p.status, 0) << p.err;
        return std::stod(p.out.substr(p.out.find("\n\n") + 2));
    };
    EXPECT_NEAR(first_pixel("da.hdr"), 40, 0.4);
    // Illuminance from a matrix column goes in as W/m2 (lux / 179); 09:30 is 400 lux.
    ASSERT_EQ(Run("fcplan -i s.pts -c 9 -px 1 -hdr h.hdr total.mtx").status, 0);
    EXPECT_NEAR(first_pixel("h.hdr") * 179, 400, 4);
    struct Case {
        std::string cmd, message;
    };
    const Case cases[] = {
        {"fcplan -i two.pts -c DA -o x.png m.csv", "m.csv: 3 values for 2 sensors in two.pts"},
        {"fcplan -i s.pts -c DB -o x.png m.csv", "m.csv:1: no column named 'DB'"},
        {"fcplan -i s.pts -c 9000 -o x.png total.mtx", "-c 9000: columns are numbered 0 to 8759"},
        {"fcplan -i s.pts -c DA m.csv", "no output"},
        {"fcplan -i none.pts -c DA -o x.png m.csv", "none.pts"},
    };
    for (const Case &c : cases) {
        CommandResult e = Run(c.cmd);
        EXPECT_EQ(e.status, 1) << c.cmd;
        EXPECT_NE(e.err.find(c.message), std::string::npos) << c.cmd << ": " << e.err;
        EXPECT_FALSE(fs::exists(tmp_.path() / "x.png")) << c.cmd;
    }
}

}  // namespace
}  // namespace dayflux::test
