#include "metrics/annual.h"

#include <algorithm>
#include <cmath>

#include "util/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

std::vector<TimeStep> HourlyYear(bool leap) {
    static constexpr int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    std::vector<TimeStep> steps;
    steps.reserve(leap ? 8784 : 8760);
    for (int m = 1; m <= 12; ++m) {
        const int days = kDays[m - 1] + (leap && m == 2 ? 1 : 0);
        for (int d = 1; d <= days; ++d)
            for (int h = 0; h < 24; ++h) steps.push_back(TimeStep{m, d, h + 0.5});
    }
    return steps;
}

std::vector<double> DailySchedule(const std::vector<TimeStep> &steps, double start, double end) {
    std::vector<double> w(steps.size());
    for (size_t i = 0; i < steps.size(); ++i)
        w[i] = steps[i].hour >= start && steps[i].hour < end ? 1. : 0.;
    return w;
}

std::vector<double> ReadSchedule(const std::string &path, size_t expected_steps) {
    auto in = InputSource::Open(path);
    std::vector<double> w;
    std::string line;
    bool first = true;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        const size_t end = line.find_last_not_of(" \t\r");
        if (end == std::string::npos) continue;  // blank line
        const size_t sep = line.find_last_of(" \t,;", end);
        const size_t from = sep == std::string::npos ? 0 : sep + 1;
        const std::string field = line.substr(from, end + 1 - from);
        double v;
        if (!ParseNumber(field, &v)) {
            if (first) {  // a CSV header
                first = false;
                continue;
            }
            ErrorExit(&loc, "occupancy '" + field + "' is not a number");
        }
        first = false;
        if (!(v >= 0 && v <= 1)) ErrorExit(&loc, "occupancy " + field + " is outside 0..1");
        w.push_back(v);
    }
    in->Close();
    if (w.size() != expected_steps)
        ErrorExit(in->Name() + ": " + std::to_string(w.size()) + " occupancy values for " +
                  std::to_string(expected_steps) + " time steps");
    return w;
}

AnnualMetrics::AnnualMetrics(int sensors, std::vector<double> occupancy, const MetricThresholds &t)
    : occupancy_(std::move(occupancy)), t_(t), counts_(sensors) {
    for (double w : occupancy_) occupied_ += w;
}

SensorMetrics AnnualMetrics::Sensor(int sensor) const {
    const Counts &c = counts_[sensor];
    SensorMetrics m;
    if (occupied_ <= 0) return m;
    const double pct = 100. / occupied_;
    m.da = c.da * pct;
    m.cda = c.cda * pct;
    // Occupied steps with no value (sun down, left out of the matrix) are below any threshold.
    m.udi_lower = (c.udi_lower + (occupied_ - c.seen)) * pct;
    m.udi = c.udi * pct;
    m.udi_upper = c.udi_upper * pct;
    if (has_direct_) m.ase_hours = c.ase;
    return m;
}

GridMetrics AnnualMetrics::Grid(const std::string &name, int first, int count,
                                const std::vector<double> &areas) const {
    CHECK(first >= 0 && count > 0 && first + count <= Sensors());
    CHECK(areas.empty() || static_cast<int>(areas.size()) == Sensors());
    GridMetrics g;
    g.name = name;
    g.first = first;
    g.count = count;
    double sda = 0, ase = 0;
    for (int i = first; i < first + count; ++i) {
        const double a = areas.empty() ? 1. : areas[i];
        const SensorMetrics m = Sensor(i);
        g.area += a;
        // Shares of hours are sums of weights divided by another sum: compare with a little
        // slack, so that exactly half of 2610 hours, or of 0.1-weighted hours, counts as half.
        if (m.da >= t_.sda_percent - 1e-9 * std::max(1.0, t_.sda_percent)) sda += a;
        if (m.ase_hours > t_.ase_hours + 1e-9 * std::max(1.0, t_.ase_hours)) ase += a;
        g.mean_da += a * m.da;
        g.mean_cda += a * m.cda;
        g.mean_udi_lower += a * m.udi_lower;
        g.mean_udi += a * m.udi;
        g.mean_udi_upper += a * m.udi_upper;
    }
    CHECK(g.area > 0);
    const double k = 1. / g.area;
    g.sda = 100. * sda * k;
    g.ase = has_direct_ ? 100. * ase * k : -1.;
    g.mean_da *= k;
    g.mean_cda *= k;
    g.mean_udi_lower *= k;
    g.mean_udi *= k;
    g.mean_udi_upper *= k;
    return g;
}

}  // namespace dayflux
