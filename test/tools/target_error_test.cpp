// rcontrib-gpu -target_error: sensors traced until their estimated error reaches the target (or
// the cap), with estimates that are honest against a converged answer, and the same bytes for any
// thread count and any sharding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace dayflux::test {
namespace {
namespace fs = std::filesystem;

const std::string kRoom =
    "-m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad";

fs::path Room() { return DataDir() / "scene" / "models" / "room"; }
std::string Points() { return (DataDir() / "rcontrib" / "points.txt").string(); }

// Each line's luminance (three numbers).
std::vector<double> Luminances(const std::string &text) {
    std::vector<double> v;
    std::istringstream in(text);
    for (double r, g, b; in >> r >> g >> b;) v.push_back(0.265 * r + 0.670 * g + 0.065 * b);
    return v;
}

// Every sensor stops at the target or at the cap, and its estimated error is honest: measured
// against the converged answer, 92 % of sensors are within twice their estimate (issue 45 asks
// 90 %; bench/target_error_speed_error.sh measures it on 6724 sensor runs); of these 100, at
// least 84 (92 less three binomial standard deviations, 2.7 each). The summary counts as at the
// target every sensor that stopped before the cap, and none whose estimate is above it. -se
// gives each entry's standard error from the same passes: under this one-column sky, the
// report's relative error times the value.
TEST(TargetError, SensorsStopAtTheTargetWithHonestErrors) {
    TempDir tmp;
    const fs::path report = tmp.path() / "report.txt", se = tmp.path() / "se.txt";
    const CommandResult r = RunCommand(
        "rcontrib-gpu -h -I+ -ab 2 -ad 4096 -lw 1e-5 "
        "-target_error 0.03 -se '" +
            se.string() + "' -target_report '" + report.string() + "' " + kRoom + " < '" +
            Points() + "'",
        Room());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("-target_error 0.03: "), std::string::npos) << r.err;
    const std::vector<double> ours = Luminances(r.out),
                              answer = Luminances(
                                  ReadFile(DataDir() / "target_error" / "room_converged.txt"));
    const std::vector<TargetReportSensor> sensors = ReadTargetReport(report);
    const std::vector<double> errors = Luminances(ReadFile(se));
    ASSERT_EQ(errors.size(), 100u);
    ASSERT_EQ(ours.size(), 100u);
    ASSERT_EQ(answer.size(), 100u);
    ASSERT_EQ(sensors.size(), 100u);
    int honest = 0, early = 0, below = 0;
    for (size_t i = 0; i < ours.size(); ++i) {
        const TargetReportSensor &s = sensors[i];
        EXPECT_TRUE(s.error <= 0.03 || s.samples == 4096) << i;
        EXPECT_LE(s.samples, 4096);
        early += s.samples < 4096;
        below += s.error <= 0.03;
        honest += std::fabs(ours[i] / answer[i] - 1) <= 2 * s.error;
        EXPECT_NEAR(errors[i], s.error * ours[i], 1e-5 * errors[i]) << i;
    }
    EXPECT_GE(honest, 84);
    EXPECT_GT(early, 20);  // the target was reached, and saved samples, where it could be
    int at_target = -1, of = 0;
    std::sscanf(r.err.c_str() + r.err.find("-target_error 0.03: "),
                "-target_error 0.03: %d of %d sensors at the target", &at_target, &of);
    EXPECT_EQ(of, 100) << r.err;
    EXPECT_GE(at_target, early) << r.err;  // (those at the cap: their error's bound decides)
    EXPECT_LE(at_target, below) << r.err;
}

// The same bytes on one thread and two, and when the sensors are traced as two shards.
TEST(TargetError, SameBytesForAnyThreadsAndShards) {
    const std::string run = "rcontrib-gpu -h -I+ -ab 2 -ad 1024 -lw 1e-4 -target_error 0.05 ";
    const auto trace = [&](const std::string &how, const std::string &input) {
        const CommandResult r = RunCommand(input + " | " + run + how + " " + kRoom, Room());
        EXPECT_EQ(r.status, 0) << r.err;
        return r.out;
    };
    const std::string points = "'" + Points() + "'";
    const std::string one = trace("-n 1", "cat " + points), two = trace("-n 2", "cat " + points);
    EXPECT_EQ(one, two);
    const std::string first = trace("-n 2", "head -n 37 " + points),
                      second = trace("-n 2 -first_record 37", "tail -n +38 " + points);
    EXPECT_EQ(first + second, one);
    EXPECT_EQ(Luminances(one).size(), 100u);
}

// rtrace-gpu and rtrace_dc-gpu take -target_error too (with -aa 0: it replaces the cache), and
// rfluxmtx-gpu passes it to rcontrib's engine.
TEST(TargetError, RtraceRtraceDcAndRfluxmtxTakeIt) {
    TempDir tmp;
    const std::string scene = "materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad";
    const std::string points = "'" + Points() + "'";
    const std::string report = (tmp.path() / "r.txt").string();
    CommandResult r = RunCommand(
        "rtrace-gpu -h -I -ab 2 -aa 0 -ad 1024 -lw 1e-4 -target_error "
        "0.05 -target_report '" +
            report + "' " + scene + " < " + points,
        Room());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("rtrace-gpu: -target_error 0.05: "), std::string::npos) << r.err;
    EXPECT_EQ(Luminances(r.out).size(), 100u);
    EXPECT_EQ(ReadTargetReport(report).size(), 100u);
    r = RunCommand("rtrace-gpu -h -I -ab 2 -aa 0.1 -target_error 0.05 " + scene + " < " + points,
                   Room());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("without the ambient cache"), std::string::npos) << r.err;
    r = RunCommand("head -n 3 " + points +
                       " | rtrace_dc-gpu -h -I+ -oc -aa 0 -ab 2 -ad 256 -N 148 "
                       "-Dd -target_error 0.1 " +
                       scene,
                   Room());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("3 sensors"), std::string::npos) << r.err;
    r = RunCommand("head -n 3 " + points +
                       " | rfluxmtx-gpu -h -I+ -ab 2 -ad 256 -lw 1e-3 "
                       "-target_error 0.1 - skyDomes/skyglow.rad materials.rad room.rad "
                       "objects/Glazing.rad",
                   Room());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("-target_error 0.1: "), std::string::npos) << r.err;
}

TEST(TargetError, OptionsThatDoNotGoTogetherAreRefused) {
    for (const char *bad :
         {"-target_error 0 ", "-target_error 2 ", "-max_samples 100 ",
          "-target_error 0.05 -sensor_cache 0.1 ", "-target_error 0.05 -max_samples 4 "}) {
        const CommandResult r =
            RunCommand(std::string("rcontrib-gpu -I+ ") + bad + kRoom + " < /dev/null", Room());
        EXPECT_EQ(r.status, 1) << bad;
        EXPECT_EQ(r.out, "") << bad;
    }
}

}  // namespace
}  // namespace dayflux::test
