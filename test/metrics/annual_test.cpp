// Annual metrics on hand-made series with known answers: every threshold edge, night hours,
// leap years, schedules and area weights.
#include "metrics/annual.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"
#include "util/errors.h"

namespace dayflux::test {
namespace {

// A year in which every sensor sees the same illuminance at every hour.
AnnualMetrics ConstantYear(const std::vector<double> &lux, bool leap = false) {
    const auto steps = HourlyYear(leap);
    AnnualMetrics m(static_cast<int>(lux.size()), DailySchedule(steps, 8, 18), {});
    for (int s = 0; s < static_cast<int>(lux.size()); ++s)
        for (int t = 0; t < static_cast<int>(steps.size()); ++t) m.AddTotal(s, t, lux[s]);
    return m;
}

TEST(Calendar, HourlyYearsAndLm83Schedule) {
    EXPECT_EQ(HourlyYear(false).size(), 8760u);
    const auto leap = HourlyYear(true);
    ASSERT_EQ(leap.size(), 8784u);
    EXPECT_EQ(leap[59 * 24].month, 2);
    EXPECT_EQ(leap[59 * 24].day, 29);
    EXPECT_EQ(leap.back().month, 12);
    EXPECT_EQ(leap.back().day, 31);
    EXPECT_DOUBLE_EQ(leap.back().hour, 23.5);
    // 08:00-18:00: the steps at 8.5 .. 17.5, ten a day.
    const auto w = DailySchedule(HourlyYear(false), 8, 18);
    double sum = 0;
    for (double x : w) sum += x;
    EXPECT_EQ(sum, 3650);
    EXPECT_EQ(w[7], 0);   // 07:30
    EXPECT_EQ(w[8], 1);   // 08:30
    EXPECT_EQ(w[17], 1);  // 17:30
    EXPECT_EQ(w[18], 0);  // 18:30
    AnnualMetrics m = ConstantYear({500}, true);
    EXPECT_EQ(m.OccupiedHours(), 3660);
}

TEST(AnnualMetrics, ThresholdEdges) {
    // DA counts E >= 300; UDI is 100 <= E <= 3000, lower E < 100, upper E > 3000.
    const std::vector<double> lux = {
        300,  std::nextafter(300., 0.),   100, std::nextafter(100., 0.),
        3000, std::nextafter(3000., 1e9), 0,   150};
    AnnualMetrics m = ConstantYear(lux);
    const SensorMetrics at300 = m.Sensor(0), below300 = m.Sensor(1);
    EXPECT_DOUBLE_EQ(at300.da, 100);
    EXPECT_DOUBLE_EQ(at300.cda, 100);
    EXPECT_DOUBLE_EQ(below300.da, 0);
    EXPECT_NEAR(below300.cda, 100, 1e-9);
    EXPECT_LT(below300.cda, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(2).udi, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(3).udi_lower, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(4).udi, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(5).udi_upper, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(6).udi_lower, 100);
    EXPECT_DOUBLE_EQ(m.Sensor(6).cda, 0);
    EXPECT_DOUBLE_EQ(m.Sensor(7).cda, 50);  // min(1, 150/300)
    for (int s = 0; s < m.Sensors(); ++s) {
        const SensorMetrics x = m.Sensor(s);
        EXPECT_NEAR(x.udi_lower + x.udi + x.udi_upper, 100, 1e-9) << s;
        EXPECT_EQ(x.ase_hours, -1) << "no direct-sun data was given";
    }
    EXPECT_EQ(m.Grid("g", 0, m.Sensors(), {}).ase, -1);
}

TEST(AnnualMetrics, UnoccupiedAndMissingHours) {
    // Bright only at night and at weekends of nobody: unoccupied hours never count; occupied
    // hours with no value (sun down, left out of a gendaymtx -u matrix) count as dark.
    const auto steps = HourlyYear(false);
    AnnualMetrics m(2, DailySchedule(steps, 8, 18), {});
    for (int t = 0; t < 8760; ++t) {
        const bool occupied = steps[t].hour > 8 && steps[t].hour < 18;
        m.AddTotal(0, t, occupied ? 0. : 1e5);
        if (steps[t].hour < 12) m.AddTotal(1, t, 500);  // afternoons missing
    }
    EXPECT_DOUBLE_EQ(m.Sensor(0).da, 0);
    EXPECT_DOUBLE_EQ(m.Sensor(0).udi_upper, 0);
    const SensorMetrics half = m.Sensor(1);
    EXPECT_DOUBLE_EQ(half.da, 40);  // 08:30..11:30 is 4 of the 10 occupied hours
    EXPECT_DOUBLE_EQ(half.udi, 40);
    EXPECT_DOUBLE_EQ(half.udi_lower, 60);
}

TEST(AnnualMetrics, SdaAndAseEdges) {
    // Four sensors: DA exactly 50 % (passes sDA), DA just under 50 %, and ASE hours at exactly
    // 250 (passes: LM-83 fails a point only above 250) and 251 (fails); direct light of exactly
    // 1000 lux is not above 1000.
    const auto steps = HourlyYear(false);
    AnnualMetrics m(4, DailySchedule(steps, 8, 18), {});
    int occupied = 0;
    for (int t = 0; t < 8760; ++t) {
        if (!(steps[t].hour > 8 && steps[t].hour < 18)) continue;
        m.AddTotal(0, t, occupied < 1825 ? 400 : 10);
        m.AddTotal(1, t, occupied < 1824 ? 400 : 10);
        m.AddDirect(0, t, 1000);
        m.AddDirect(1, t, occupied < 250 ? 1001 : 0);
        m.AddDirect(2, t, occupied < 251 ? 1001 : 0);
        ++occupied;
    }
    EXPECT_DOUBLE_EQ(m.Sensor(0).da, 50);
    EXPECT_LT(m.Sensor(1).da, 50);
    EXPECT_EQ(m.Sensor(0).ase_hours, 0);
    EXPECT_EQ(m.Sensor(1).ase_hours, 250);
    EXPECT_EQ(m.Sensor(2).ase_hours, 251);
    const GridMetrics g = m.Grid("office", 0, 4, {});
    EXPECT_DOUBLE_EQ(g.sda, 25);
    EXPECT_DOUBLE_EQ(g.ase, 25);
    // Area weights: the failing sensor holds 3 of 6 m2.
    const GridMetrics w = m.Grid("office", 0, 4, {1, 1, 3, 1});
    EXPECT_DOUBLE_EQ(w.area, 6);
    EXPECT_DOUBLE_EQ(w.ase, 50);
    EXPECT_DOUBLE_EQ(w.sda, 100. / 6.);
    // A sub-grid.
    const GridMetrics tail = m.Grid("tail", 2, 2, {});
    EXPECT_DOUBLE_EQ(tail.ase, 50);
    EXPECT_DOUBLE_EQ(tail.sda, 0);
}

TEST(AnnualMetrics, ThresholdsSurviveRounding) {
    // Weekdays 08:00-18:00 of a year starting on a Monday: 261 days, 2610 hours. Exactly half of
    // them bright gives DA 50 % after division, which must still pass sDA's >= 50 %; with every
    // hour weighted 0.1, 250 weighted hours of direct sun must not count as more than 250.
    const auto steps = HourlyYear(false);
    std::vector<double> weekdays = DailySchedule(steps, 8, 18);
    for (size_t t = 0; t < steps.size(); ++t)
        if ((t / 24) % 7 >= 5) weekdays[t] = 0;
    AnnualMetrics m(1, weekdays, {});
    ASSERT_DOUBLE_EQ(m.OccupiedHours(), 2610);
    int occupied = 0;
    for (int t = 0; t < 8760; ++t)
        if (weekdays[t] > 0) m.AddTotal(0, t, occupied++ < 1305 ? 500 : 0);
    EXPECT_EQ(m.Grid("g", 0, 1, {}).sda, 100);
    std::vector<double> tenth(8760, 0.1);
    AnnualMetrics f(1, tenth, {});
    for (int t = 0; t < 8760; ++t) f.AddTotal(0, t, t < 4380 ? 500 : 0);
    for (int t = 0; t < 2500; ++t) f.AddDirect(0, t, 2000);
    EXPECT_EQ(f.Grid("g", 0, 1, {}).sda, 100);
    EXPECT_EQ(f.Grid("g", 0, 1, {}).ase, 0) << f.Sensor(0).ase_hours;
    f.AddDirect(0, 2500, 2000);
    EXPECT_EQ(f.Grid("g", 0, 1, {}).ase, 100);
}

TEST(AnnualMetrics, FractionalOccupancyWeightsHours) {
    // Half-occupied hours count half: DA is the weighted share of hours.
    std::vector<double> w = {1, 0.5, 0.5, 0};
    AnnualMetrics m(1, w, {});
    m.AddTotal(0, 0, 1000);
    m.AddTotal(0, 1, 1000);
    m.AddTotal(0, 2, 0);
    m.AddTotal(0, 3, 1000);
    EXPECT_DOUBLE_EQ(m.OccupiedHours(), 2);
    EXPECT_DOUBLE_EQ(m.Sensor(0).da, 75);
}

TEST(Schedules, ReadAndReject) {
    TempDir dir;
    WriteFile(dir.path() / "ok.csv", "hour,occupied\n1,0\n2,1\n3,0.5\n");
    const auto w = ReadSchedule((dir.path() / "ok.csv").string(), 3);
    EXPECT_EQ(w, (std::vector<double>{0, 1, 0.5}));
    EXPECT_THROW(ReadSchedule((dir.path() / "ok.csv").string(), 4), UserError);
    WriteFile(dir.path() / "bad.txt", "1\n2\n");
    try {
        ReadSchedule((dir.path() / "bad.txt").string(), 2);
        ADD_FAILURE() << "an occupancy of 2 was accepted";
    } catch (const UserError &e) {
        EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
    }
    WriteFile(dir.path() / "word.txt", "1\nx\n");
    EXPECT_THROW(ReadSchedule((dir.path() / "word.txt").string(), 2), UserError);
}

}  // namespace
}  // namespace dayflux::test
