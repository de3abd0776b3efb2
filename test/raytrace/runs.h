// Running rcontrib-gpu from the integrator tests and reading what it gives: each record's total,
// the mean of many records and its standard error.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace dayflux::test {

// A uniform glow sky of radiance 1 over the upper hemisphere, modifier `skyglow`.
inline const char *kSky = "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n";

// The numbers of a program's ascii output, in order.
inline std::vector<double> NumbersIn(const std::string &text) {
    std::istringstream ss(text);
    std::vector<double> v;
    for (double x; ss >> x;) v.push_back(x);
    return v;
}

// Runs `program args < rays` in dir on `count` copies of one sensor ray (each with its own random
// numbers; ascii output without header) and returns each record's total over its columns (first
// component); none if the run failed.
inline std::vector<double> RecordTotals(const std::filesystem::path &dir,
                                        const std::string &program, const std::string &args,
                                        int count, const std::string &ray) {
    std::string rays;
    for (int i = 0; i < count; ++i) rays += ray + "\n";
    WriteFile(dir / "rays", rays);
    const CommandResult r = RunCommand(program + " -h -faa " + args + " < rays", dir);
    EXPECT_EQ(r.status, 0) << program << " " << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("using Embree"), std::string::npos) << r.err;  // the backend asked for
    const std::vector<double> v = NumbersIn(r.out);
    if (r.status != 0 || v.empty() || v.size() % (3 * static_cast<size_t>(count)) != 0) return {};
    std::vector<double> totals(count, 0.0);
    const size_t per = v.size() / count;
    for (int i = 0; i < count; ++i)
        for (size_t k = 0; k < per; k += 3) totals[i] += v[i * per + k];
    return totals;
}

inline void MeanAndStandardError(const std::vector<double> &x, double *mean, double *se) {
    double s = 0, ss = 0;
    for (double v : x) s += v;
    *mean = s / x.size();
    for (double v : x) ss += (v - *mean) * (v - *mean);
    *se = std::sqrt(ss / (x.size() - 1) / x.size());
}

// The mean of `count` runs for an upward sensor at the origin (each with its own random numbers)
// and its standard error; NaNs, which fail every comparison, if it failed.
struct MeanAndError {
    double mean, se;
};
inline MeanAndError UpwardSensorMean(const std::filesystem::path &dir, const std::string &program,
                                     const std::string &args, int count) {
    const std::vector<double> t = RecordTotals(dir, program, args, count, "0 0 0 0 0 1");
    EXPECT_EQ(t.size(), static_cast<size_t>(count)) << args;
    if (t.size() != static_cast<size_t>(count)) return {NAN, NAN};
    MeanAndError m;
    MeanAndStandardError(t, &m.mean, &m.se);
    return m;
}

}  // namespace dayflux::test
