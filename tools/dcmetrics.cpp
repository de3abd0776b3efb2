// dcmetrics: annual daylight metrics (DA, cDA, UDI, sDA, ASE) from the illuminance matrices of a
// daylight-coefficient or multi-phase run, per sensor and per grid, as text, CSV and JSON.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "matrix/reader.h"
#include "metrics/annual.h"
#include "sky/solar.h"
#include "sky/weather.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/options.h"
#include "util/photometry.h"
#include "util/strings.h"

namespace dayflux {
namespace {

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-t][-w weather [-u]][-occ start end | -s schedule][-da lux][-udi low high]"
              "[-sda percent][-ase lux hours][-a areas][-g name count ...][-e errors][-o prefix] "
              "illuminance [direct_sun_illuminance]");
}

struct Grid {
    std::string name;
    int count = 0;
};

struct Options {
    bool steps_are_rows = false;
    std::string weather, schedule, areas, prefix;
    bool sun_up_only = false;
    double occ_start = 8, occ_end = 18;
    MetricThresholds t;
    std::vector<Grid> grids;
    std::string total, direct;
    // -e: each sensor's relative standard error (rcontrib-gpu -target_report's lines: sensor,
    // samples, error), propagated to DA and sDA by resampling (docs/metrics.md)
    std::string errors;
};

// Resamples of the illuminance within the sensors' errors: each sensor's whole year scaled by
// 1 + error z (z normal, from a fixed seed: the same uncertainties every run).
constexpr int kResamples = 50;

double Number(int argc, char **argv, int *i) { return OptionNumber(argc, argv, i, Usage); }

Options ParseOptions(int argc, char **argv) {
    Options o;
    int i = 1;
    for (; i < argc && argv[i][0] == '-' && argv[i][1]; ++i) {
        const std::string a = argv[i];
        if (a == "-t") {
            o.steps_are_rows = true;
        } else if (a == "-w" && i + 1 < argc) {
            o.weather = argv[++i];
        } else if (a == "-u") {
            o.sun_up_only = true;
        } else if (a == "-occ") {
            o.occ_start = Number(argc, argv, &i);
            o.occ_end = Number(argc, argv, &i);
        } else if (a == "-s" && i + 1 < argc) {
            o.schedule = argv[++i];
        } else if (a == "-da") {
            o.t.da_lux = Number(argc, argv, &i);
        } else if (a == "-udi") {
            o.t.udi_lower = Number(argc, argv, &i);
            o.t.udi_upper = Number(argc, argv, &i);
        } else if (a == "-sda") {
            o.t.sda_percent = Number(argc, argv, &i);
        } else if (a == "-ase") {
            o.t.ase_lux = Number(argc, argv, &i);
            o.t.ase_hours = Number(argc, argv, &i);
        } else if (a == "-a" && i + 1 < argc) {
            o.areas = argv[++i];
        } else if (a == "-g" && i + 2 < argc) {
            Grid g{argv[i + 1], 0};
            if (g.name.empty() || g.name.find_first_of(",\"\n\r") != std::string::npos)
                ErrorExit("-g '" + g.name +
                          "': a grid name must be non-empty, without commas, quotes or newlines "
                          "(it is a CSV field)");
            if (!ParseInt(argv[i + 2], &g.count) || g.count <= 0)
                ErrorExit(std::string("-g ") + argv[i + 1] + ": '" + argv[i + 2] +
                          "' is not a positive sensor count");
            o.grids.push_back(g);
            i += 2;
        } else if (a == "-o" && i + 1 < argc) {
            o.prefix = argv[++i];
        } else if (a == "-e" && i + 1 < argc) {
            o.errors = argv[++i];
        } else {
            Usage(argv[0]);
        }
    }
    if (i == argc || argc - i > 2) Usage(argv[0]);
    o.total = argv[i];
    if (i + 1 < argc) o.direct = argv[i + 1];
    if (o.sun_up_only && o.weather.empty()) ErrorExit("-u needs the weather file (-w)");
    if (!(o.occ_start < o.occ_end)) ErrorExit("-occ: the start must come before the end");
    if (!(o.t.udi_lower < o.t.udi_upper))
        ErrorExit("-udi: the lower limit must be below the upper");
    return o;
}

// The year's time steps, and for each matrix step the index of its time step.
struct Calendar {
    std::vector<TimeStep> steps;
    std::vector<int> step_of_column;
    std::string description;
    double hours_per_step = 1;
};

Calendar ReadCalendar(const Options &o, int matrix_steps, const std::string &matrix_name) {
    Calendar c;
    if (o.weather.empty()) {
        if (matrix_steps != 8760 && matrix_steps != 8784)
            ErrorExit(matrix_name + ": " + std::to_string(matrix_steps) +
                      " time steps is not an hourly year (8760 or 8784): give the weather "
                      "file with -w");
        c.steps = HourlyYear(matrix_steps == 8784);
        for (int j = 0; j < matrix_steps; ++j) c.step_of_column.push_back(j);
        c.description = "an hourly year";
        return c;
    }
    WeatherReader weather(o.weather);
    const WeatherHeader &wh = weather.Header();
    SunTrack sun(
        Site{wh.latitude * M_PI / 180., wh.longitude * M_PI / 180., wh.time_zone * M_PI / 180.});
    WeatherRecord rec;
    int sun_up = 0;
    double step = 1;  // hours between records of one day, for .wea files with sub-hourly data
    bool step_known = false;
    while (weather.Next(&rec)) {
        if (!step_known && !c.steps.empty() && c.steps.back().month == rec.month &&
            c.steps.back().day == rec.day && rec.hour > c.steps.back().hour) {
            step = std::min(1.0, rec.hour - c.steps.back().hour);
            step_known = true;
        }
        const bool up = sun.Next(rec.month, rec.day, rec.hour).in_sky;
        if (up) ++sun_up;
        if (!o.sun_up_only || up) c.step_of_column.push_back(static_cast<int>(c.steps.size()));
        c.steps.push_back(TimeStep{rec.month, rec.day, rec.hour});
    }
    if (static_cast<int>(c.step_of_column.size()) != matrix_steps) {
        std::string hint = o.sun_up_only ? " (without -u: " + std::to_string(c.steps.size()) + ")"
                                         : " (" + std::to_string(sun_up) +
                                               " with the sun up: was the sky made with "
                                               "gendaymtx -u? then give -u)";
        ErrorExit(matrix_name + ": " + std::to_string(matrix_steps) + " time steps, but " +
                  weather.Name() + " gives " + std::to_string(c.step_of_column.size()) + hint);
    }
    // Sub-hourly weather: each step counts for its share of an hour, so occupied hours and ASE's
    // 250 hours stay hours.
    c.hours_per_step = wh.records_per_hour > 1 ? 1.0 / wh.records_per_hour : step;
    c.description = weather.Name();
    return c;
}

// One illuminance matrix, streamed into the metrics; returns its sensor count.
struct MatrixShape {
    int sensors = 0, steps = 0;
};

// The shape of an illuminance matrix from its header (the data is read once, by Stream).
MatrixShape ShapeOf(const MatrixReader &r, const Options &o, const MatrixShape *expect) {
    const int nc = r.Comps();
    if (nc != 1 && nc != 3)
        ErrorExit(r.Name() + ": NCOMP=" + std::to_string(nc) +
                  ": expected illuminance (1 component) or RGB irradiance (3)");
    MatrixShape shape;
    shape.sensors = o.steps_are_rows ? r.Cols() : r.Rows();
    shape.steps = o.steps_are_rows ? r.Rows() : r.Cols();
    if (r.Rows() == 0) ErrorExit(r.Name() + ": the number of rows (NROWS=) is needed");
    if (expect && (shape.sensors != expect->sensors || shape.steps != expect->steps))
        ErrorExit(r.Name() + ": " + std::to_string(shape.sensors) + " sensors x " +
                  std::to_string(shape.steps) + " time steps, but the illuminance matrix has " +
                  std::to_string(expect->sensors) + " x " + std::to_string(expect->steps));
    return shape;
}

// Illuminance below zero is no light at all: the five-phase sum (VTDS - V_d T D_d S + C_ds S_sun)
// gives small negative values where its terms' noise does not cancel. They count as 0 (RADIANCE
// tools would average them in), with one warning saying how many and the worst.
class NegativeValues {
  public:
    double Clamp(double e, int row, int col) {
        if (count_++ == 0 || e < worst_) worst_ = e, row_ = row, col_ = col;
        return 0;
    }
    void Report(const std::string &name) const {
        if (count_ == 0) return;
        Warning(name + ": " + std::to_string(count_) +
                " negative illuminance value(s) taken as 0 (the lowest, " + FormatNumber(worst_) +
                " lux, at row " + std::to_string(row_ + 1) + " column " + std::to_string(col_ + 1) +
                ")");
    }

  private:
    long count_ = 0;
    double worst_ = 0;
    int row_ = 0, col_ = 0;
};

// -e's file: each sensor's relative standard error, in sensor order.
std::vector<double> ReadErrors(const std::string &path, int sensors) {
    auto in = InputSource::Open(path);
    std::vector<double> errors;
    std::string line;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line);
        std::string w[4];
        words >> w[0] >> w[1] >> w[2] >> w[3];
        int sensor = -1;
        double samples = 0, error = -1;
        if (!ParseInt(w[0], &sensor) || !ParseNumber(w[1], &samples) ||
            !ParseNumber(w[2], &error) || !w[3].empty() ||
            sensor != static_cast<int>(errors.size()) || !(error >= 0) || !std::isfinite(error))
            ErrorExit(&loc, "expected sensor " + std::to_string(errors.size()) +
                                ", its samples and a relative error of 0 or more");
        errors.push_back(error);
    }
    if (static_cast<int>(errors.size()) != sensors)
        ErrorExit(in->Name() + ": errors for " + std::to_string(errors.size()) + " sensors, not " +
                  std::to_string(sensors));
    return errors;
}

// The scale of each resample's sensors: factors[k][sensor] = max(0, 1 + error z).
std::vector<std::vector<double>> ResampleFactors(const std::vector<double> &errors) {
    std::mt19937_64 random(20261129);
    std::normal_distribution<double> normal;
    std::vector<std::vector<double>> f(kResamples, std::vector<double>(errors.size()));
    for (auto &resample : f)
        for (size_t i = 0; i < errors.size(); ++i)
            resample[i] = std::max(0.0, 1 + errors[i] * normal(random));
    return f;
}

double StandardDeviation(const std::vector<double> &v) {
    double m = 0, q = 0;
    for (double x : v) m += x;
    m /= v.size();
    for (double x : v) q += (x - m) * (x - m);
    return v.size() > 1 ? std::sqrt(q / (v.size() - 1)) : 0;
}

// -e: the metrics of each resample.
struct Resampled {
    std::vector<std::vector<double>> factors;
    std::vector<AnnualMetrics> metrics;
};

// Streams a matrix into the metrics, as total or as direct-sun illuminance (and the total into
// each resample's).
void Stream(MatrixReader &r, const Options &o, const Calendar &calendar, bool direct,
            AnnualMetrics *metrics, Resampled *resampled = nullptr) {
    const int nc = r.Comps();
    const std::vector<int> &col_step = calendar.step_of_column;
    std::vector<double> row(static_cast<size_t>(r.Cols()) * nc);
    NegativeValues negatives;
    for (int i = 0; i < r.Rows(); ++i) {
        r.ReadRow(row.data());
        for (int j = 0; j < r.Cols(); ++j) {
            const double *v = &row[static_cast<size_t>(j) * nc];
            double e = nc == 1 ? v[0] : IlluminanceFromRgb(v);
            if (!std::isfinite(e))
                ErrorExit(r.Name() + ": row " + std::to_string(i + 1) + " column " +
                          std::to_string(j + 1) + " is not a finite number");
            if (e < 0) e = negatives.Clamp(e, i, j);
            const int sensor = o.steps_are_rows ? j : i;
            const int step = col_step[o.steps_are_rows ? i : j];
            if (direct) {
                metrics->AddDirect(sensor, step, e);
            } else {
                metrics->AddTotal(sensor, step, e);
                if (resampled)
                    for (int k = 0; k < kResamples; ++k)
                        resampled->metrics[k].AddTotal(sensor, step,
                                                       e * resampled->factors[k][sensor]);
            }
        }
    }
    negatives.Report(r.Name());
    r.Finish(true);
}

std::vector<double> ReadAreas(const std::string &path, int sensors) {
    auto in = InputSource::Open(path);
    std::vector<double> a;
    std::string_view word;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->NextWord(&word)) break;
        double v;
        if (!ParseNumber(word, &v) || !(v > 0) || !std::isfinite(v))
            ErrorExit(&loc, "sensor area '" + std::string(word) + "' is not a positive number");
        a.push_back(v);
    }
    in->Close();
    if (static_cast<int>(a.size()) != sensors)
        ErrorExit(in->Name() + ": " + std::to_string(a.size()) + " areas for " +
                  std::to_string(sensors) + " sensors");
    return a;
}

std::string JsonString(const std::string &s) {
    std::string out = "\"";
    for (char ch : s) {
        if (ch == '"' || ch == '\\') {
            out += '\\';
            out += ch;
        } else if (static_cast<unsigned char>(ch) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", ch);
            out += buf;
        } else {
            out += ch;
        }
    }
    return out + "\"";
}

std::string Fixed(double v, int digits = 4) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

std::string JsonNumber(double v) { return v < 0 ? "null" : Fixed(v); }

// da_sd: each sensor's DA's standard deviation (-e), or empty.
void WriteCsv(const std::string &path, const AnnualMetrics &m, const std::vector<Grid> &grids,
              const std::vector<double> &areas, bool has_direct, const std::vector<double> &da_sd) {
    OutputFile out(path);
    out.Write(std::string("grid,sensor,area,DA,cDA,UDI_lower,UDI,UDI_upper,ASE_hours") +
              (da_sd.empty() ? "\n" : ",DA_sd\n"));
    int s = 0;
    for (const Grid &g : grids) {
        for (int k = 0; k < g.count; ++k, ++s) {
            const SensorMetrics x = m.Sensor(s);
            out.Write(g.name + "," + std::to_string(s) + "," +
                      Fixed(areas.empty() ? 1. : areas[s], 6) + "," + Fixed(x.da) + "," +
                      Fixed(x.cda) + "," + Fixed(x.udi_lower) + "," + Fixed(x.udi) + "," +
                      Fixed(x.udi_upper) + "," + (has_direct ? Fixed(x.ase_hours, 2) : "") +
                      (da_sd.empty() ? "" : "," + Fixed(da_sd[s])) + "\n");
        }
    }
    out.Commit();
}

// sda_sd: each grid's sDA's standard deviation (-e), then the whole's; da_sd: each sensor's DA's.
// Both empty without -e.
void WriteJson(const std::string &path, const Options &o, const AnnualMetrics &m,
               const std::vector<GridMetrics> &gm, const GridMetrics &overall, const Calendar &cal,
               const std::vector<double> &sda_sd, const std::vector<double> &da_sd) {
    const auto sd = [&](size_t grid) {
        return sda_sd.empty() ? std::string() : ", \"sDA_sd\": " + Fixed(sda_sd[grid]);
    };
    OutputFile out(path);
    const MetricThresholds &t = o.t;
    std::string s = "{\n  \"program\": \"dcmetrics\",\n";
    s += "  \"thresholds\": {\"da_lux\": " + Fixed(t.da_lux) +
         ", \"udi_lower_lux\": " + Fixed(t.udi_lower) +
         ", \"udi_upper_lux\": " + Fixed(t.udi_upper) +
         ", \"sda_percent\": " + Fixed(t.sda_percent) + ", \"ase_lux\": " + Fixed(t.ase_lux) +
         ", \"ase_hours\": " + Fixed(t.ase_hours) + "},\n";
    s += "  \"time_steps\": " + std::to_string(cal.steps.size()) +
         ",\n  \"occupied_hours\": " + Fixed(m.OccupiedHours()) + ",\n";
    s += "  \"overall\": {\"sensors\": " + std::to_string(overall.count) +
         ", \"area\": " + Fixed(overall.area, 6) + ", \"sDA\": " + Fixed(overall.sda) +
         sd(gm.size()) + ", \"ASE\": " + JsonNumber(overall.ase) +
         ", \"mean_DA\": " + Fixed(overall.mean_da) + "},\n  \"grids\": [\n";
    for (size_t gi = 0; gi < gm.size(); ++gi) {
        const GridMetrics &g = gm[gi];
        s += "    {\"name\": " + JsonString(g.name) + ", \"sensors\": " + std::to_string(g.count) +
             ", \"area\": " + Fixed(g.area, 6) + ", \"sDA\": " + Fixed(g.sda) + sd(gi) +
             ", \"ASE\": " + JsonNumber(g.ase) + ", \"mean_DA\": " + Fixed(g.mean_da) +
             ", \"mean_cDA\": " + Fixed(g.mean_cda) +
             ", \"mean_UDI_lower\": " + Fixed(g.mean_udi_lower) +
             ", \"mean_UDI\": " + Fixed(g.mean_udi) +
             ", \"mean_UDI_upper\": " + Fixed(g.mean_udi_upper) + ",\n";
        const char *names[] = {"DA", "cDA", "UDI_lower", "UDI", "UDI_upper", "ASE_hours"};
        for (int f = 0; f < 6; ++f) {
            s += std::string("     \"") + names[f] + "\": [";
            for (int k = 0; k < g.count; ++k) {
                const SensorMetrics x = m.Sensor(g.first + k);
                const double v[] = {x.da, x.cda, x.udi_lower, x.udi, x.udi_upper, x.ase_hours};
                if (k) s += ", ";
                s += f == 5 ? JsonNumber(v[f]) : Fixed(v[f]);
            }
            s += f == 5 ? "]" : "],\n";
        }
        if (!da_sd.empty()) {
            s += ",\n     \"DA_sd\": [";
            for (int k = 0; k < g.count; ++k) s += (k ? ", " : "") + Fixed(da_sd[g.first + k]);
            s += "]";
        }
        s += "}";
        s += gi + 1 < gm.size() ? ",\n" : "\n";
    }
    s += "  ]\n}\n";
    out.Write(s);
    out.Commit();
}

int Main(int argc, char **argv) {
    Options o = ParseOptions(argc, argv);
    // Each input is opened once (it may be a pipe or stdin): headers first, then the data.
    MatrixReader total(o.total);
    const MatrixShape shape = ShapeOf(total, o, nullptr);
    std::unique_ptr<MatrixReader> direct;
    if (!o.direct.empty()) {
        direct = std::make_unique<MatrixReader>(o.direct);
        ShapeOf(*direct, o, &shape);
    }
    const Calendar cal = ReadCalendar(o, shape.steps, o.total);
    std::vector<double> occupancy = o.schedule.empty()
                                        ? DailySchedule(cal.steps, o.occ_start, o.occ_end)
                                        : ReadSchedule(o.schedule, cal.steps.size());
    for (double &w : occupancy) w *= cal.hours_per_step;
    AnnualMetrics metrics(shape.sensors, occupancy, o.t);
    if (metrics.OccupiedHours() <= 0) ErrorExit("the schedule has no occupied hours");

    if (o.grids.empty()) o.grids.push_back(Grid{"grid", shape.sensors});
    int grid_sensors = 0;
    for (const Grid &g : o.grids) grid_sensors += g.count;
    if (grid_sensors != shape.sensors)
        ErrorExit("the grids (-g) hold " + std::to_string(grid_sensors) + " sensors, but " +
                  o.total + " has " + std::to_string(shape.sensors));
    const std::vector<double> areas =
        o.areas.empty() ? std::vector<double>{} : ReadAreas(o.areas, shape.sensors);

    std::unique_ptr<Resampled> resampled;
    if (!o.errors.empty()) {
        resampled = std::make_unique<Resampled>();
        resampled->factors = ResampleFactors(ReadErrors(o.errors, shape.sensors));
        for (int k = 0; k < kResamples; ++k)
            resampled->metrics.emplace_back(shape.sensors, occupancy, o.t);
    }
    Stream(total, o, cal, false, &metrics, resampled.get());
    if (direct) Stream(*direct, o, cal, true, &metrics);
    // The spread of the resamples' sDA per grid and DA per sensor (-e).
    const auto sda_sd_of = [&](int first, int count) {
        std::vector<double> v;
        for (const AnnualMetrics &m : resampled->metrics)
            v.push_back(m.Grid("", first, count, areas).sda);
        return StandardDeviation(v);
    };
    std::vector<double> da_sd;
    if (resampled)
        for (int i = 0; i < shape.sensors; ++i) {
            std::vector<double> v;
            for (const AnnualMetrics &m : resampled->metrics) v.push_back(m.Sensor(i).da);
            da_sd.push_back(StandardDeviation(v));
        }

    std::vector<GridMetrics> gm;
    int first = 0;
    for (const Grid &g : o.grids) {
        gm.push_back(metrics.Grid(g.name, first, g.count, areas));
        first += g.count;
    }
    // Several grids: the whole as well, last, so scripts can take the last line.
    const GridMetrics overall = metrics.Grid("all", 0, shape.sensors, areas);
    std::printf("# %d sensors, %d time steps (%s), %.0f occupied hours\n", shape.sensors,
                static_cast<int>(cal.steps.size()), cal.description.c_str(),
                metrics.OccupiedHours());
    std::printf("%-12s %8s %9s %9s %8s %8s %8s %8s\n", "grid", "sensors", "sDA300/50", "ASE1k/250",
                "meanDA", "meancDA", "meanUDI", "UDI<100");
    const auto print = [](const GridMetrics &g) {
        std::printf("%-12s %8d %8.1f%% %8s %7.1f%% %7.1f%% %7.1f%% %7.1f%%\n", g.name.c_str(),
                    g.count, g.sda, g.ase < 0 ? "-" : (Fixed(g.ase, 1) + "%").c_str(), g.mean_da,
                    g.mean_cda, g.mean_udi, g.mean_udi_lower);
    };
    for (const GridMetrics &g : gm) print(g);
    if (gm.size() > 1) print(overall);
    std::vector<double> sda_sd;
    if (resampled) {
        for (const GridMetrics &g : gm) sda_sd.push_back(sda_sd_of(g.first, g.count));
        sda_sd.push_back(sda_sd_of(0, shape.sensors));
        for (size_t g = 0; g < gm.size(); ++g)
            std::printf(
                "# %s: sDA %.1f%% +- %.1f%% (one standard deviation, from the sensors' "
                "errors: %d resamples)\n",
                gm[g].name.c_str(), gm[g].sda, sda_sd[g], kResamples);
    }
    if (!o.prefix.empty()) {
        WriteCsv(o.prefix + ".csv", metrics, o.grids, areas, !o.direct.empty(), da_sd);
        WriteJson(o.prefix + ".json", o, metrics, gm, overall, cal, sda_sd, da_sd);
    }
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
