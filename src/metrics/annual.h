// Annual climate-based daylight metrics (IES LM-83 and the UDI family) from per-sensor
// illuminance time series: DA, cDA, UDI (lower, useful, upper), sDA and ASE per sensor and per
// grid. The definitions, and where common tools differ, are in docs/metrics.md.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

// One time step of the year as a weather file gives it.
struct TimeStep {
    int month = 1, day = 1;
    double hour = 0.5;  // decimal local standard time (RADIANCE's .wea hour: 8.5 = 08:00-09:00)
};

// The hourly steps of a whole year from January 1, 00:30 (8760, or 8784 with February 29).
std::vector<TimeStep> HourlyYear(bool leap);

// Occupancy weight (0..1) for each step: 1 where start <= hour < end. LM-83's default is
// 08:00-18:00 on every day, which with .wea hours at the half hour gives 10 hours a day.
std::vector<double> DailySchedule(const std::vector<TimeStep> &steps, double start, double end);

// Reads one occupancy weight per step (numbers in 0..1, one per line or the last field of a CSV
// line; a first line that is not a number is a header). Errors name file and line.
std::vector<double> ReadSchedule(const std::string &path, size_t expected_steps);

struct MetricThresholds {
    double da_lux = 300;     // DA: E >= da_lux
    double udi_lower = 100;  // UDI: udi_lower <= E <= udi_upper
    double udi_upper = 3000;
    double sda_percent = 50;  // sDA: sensors with DA >= sda_percent
    double ase_lux = 1000;    // ASE: direct-sun E > ase_lux ...
    double ase_hours = 250;   // ... for more than ase_hours occupied hours
};

struct SensorMetrics {
    double da = 0;          // % of occupied hours
    double cda = 0;         // %
    double udi_lower = 0;   // %, E < udi_lower (occupied hours after sunset included)
    double udi = 0;         // %
    double udi_upper = 0;   // %
    double ase_hours = -1;  // occupied hours with direct sun above ase_lux; -1 without direct data
};

struct GridMetrics {
    std::string name;
    int first = 0, count = 0;  // sensors [first, first + count)
    double area = 0;
    double sda = 0;   // % of area with DA >= sda_percent
    double ase = -1;  // % of area with more than ase_hours; -1 without direct data
    double mean_da = 0, mean_cda = 0, mean_udi_lower = 0, mean_udi = 0, mean_udi_upper = 0;
};

// Accumulates one sensor's illuminance over the steps, in any order of steps and sensors.
class AnnualMetrics {
  public:
    AnnualMetrics(int sensors, std::vector<double> occupancy, const MetricThresholds &t);

    int Sensors() const { return static_cast<int>(counts_.size()); }
    int Steps() const { return static_cast<int>(occupancy_.size()); }
    double OccupiedHours() const { return occupied_; }

    // Total illuminance (lux) of a sensor at a step. Steps never added count as 0 lux.
    void AddTotal(int sensor, int step, double lux) {
        const double w = occupancy_[step];
        if (w <= 0) return;
        Counts &c = counts_[sensor];
        if (lux >= t_.da_lux) c.da += w;
        c.cda += w * (lux >= t_.da_lux ? 1. : lux / t_.da_lux);
        if (lux < t_.udi_lower) {
            c.udi_lower += w;
        } else if (lux <= t_.udi_upper) {
            c.udi += w;
        } else {
            c.udi_upper += w;
        }
        c.seen += w;
    }
    // Direct-sun illuminance (lux) of a sensor at a step, for ASE.
    void AddDirect(int sensor, int step, double lux) {
        has_direct_ = true;
        const double w = occupancy_[step];
        if (w > 0 && lux > t_.ase_lux) counts_[sensor].ase += w;
    }
    void MarkDirectGiven() { has_direct_ = true; }

    SensorMetrics Sensor(int sensor) const;
    // areas: one per sensor, or empty for equal weights.
    GridMetrics Grid(const std::string &name, int first, int count,
                     const std::vector<double> &areas) const;

  private:
    struct Counts {
        double da = 0, cda = 0, udi_lower = 0, udi = 0, udi_upper = 0, ase = 0, seen = 0;
    };
    std::vector<double> occupancy_;
    MetricThresholds t_;
    double occupied_ = 0;
    bool has_direct_ = false;
    std::vector<Counts> counts_;
};

}  // namespace dayflux
