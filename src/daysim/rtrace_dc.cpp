#include "daysim/rtrace_dc.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>

#include "daysim/patches.h"
#include "matrix/reader.h"
#include "raytrace/engine.h"
#include "raytrace/sensor_cache.h"
#include "rcontrib/records.h"
#include "rcontrib/run.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/options.h"
#include "util/signals.h"
#include "util/strings.h"

namespace dayflux {

namespace {

// DAYSIM keeps at most this many coefficients (148 diffuse, or the direct run's suns).
constexpr int kMaxCoefficients = 2306;

[[noreturn]] void Usage(const std::string &prog) {
    ErrorExit("usage: " + prog +
              " [rtrace options] -N n [-Dm|-Dd] [-L lum] [-U n u1 .. un] -oc octree < rays");
}

class Parser : public RtraceLikeParser {
  public:
    Parser(std::vector<std::string> args, RtraceDcOptions *o)
        : RtraceLikeParser(std::move(args)), o_(*o) {}

    std::vector<std::string> Run() {
        std::vector<std::string> pass = RtraceLikeParser::Run();
        if (o_.coefficients < 1) ErrorExit("-N: the number of daylight coefficients is missing");
        return pass;
    }

  private:
    void Usage() const override { dayflux::Usage(Program()); }

    bool Own(const std::string &a) override {
        if (a == "-sj") {  // DAYSIM's Windows gen_dc passes the specular jitter so
            Pass("-ss", Value(a));
            return true;
        }
        return Daysim(a) || Rtrace(a);
    }

    // DAYSIM's options: -N -Dm -Dd -L -U.
    bool Daysim(const std::string &a) {
        if (a == "-N") {
            o_.coefficients = Integer(a);
            if (o_.coefficients < 1 || o_.coefficients > kMaxCoefficients)
                ErrorExit("-N " + args_[i_] +
                          ": the number of coefficients must lie between 1 and " +
                          std::to_string(kMaxCoefficients));
        } else if (a == "-Dm" || a == "-Dd") {
            o_.by_direction = a == "-Dd";
        } else if (a == "-L") {
            o_.source_luminance = Number(a);
            if (o_.source_luminance == 0 || !std::isfinite(o_.source_luminance))
                ErrorExit("-L: the sources' luminance must be a number other than zero");
        } else if (a == "-U") {
            const int n = Integer(a);
            if (n < 0) ErrorExit("-U: a negative sensor count");
            o_.sensor_units.clear();
            for (int k = 0; k < n; ++k) o_.sensor_units.push_back(Integer(a));
        } else {
            return false;
        }
        return true;
    }

    // rtrace's own options as rtrace_dc takes them.
    bool Rtrace(const std::string &a) {
        if (a.rfind("-o", 0) == 0) {
            if (a != "-oc") ErrorExit(a + ": rtrace_dc writes daylight coefficients only (-oc)");
        } else if (a.rfind("-h", 0) == 0) {
            o_.header = RtraceFlag(a, o_.header);
        } else if (a.rfind("-f", 0) == 0 && a.size() >= 3 && a.size() <= 4) {
            Formats(a);
        } else if (a.rfind("-I", 0) == 0) {
            o_.trace.contrib.irradiance = RtraceFlag(a, o_.trace.contrib.irradiance);
        } else if (a == "-cache_report") {
            o_.report_cache = true;
        } else if (a == "-x" || a == "-y") {
            Number(a);  // they shape pictures, which rtrace_dc does not write
        } else if (a == "-e") {
            ErrorExit(a + ": not supported by rtrace_dc-gpu");
        } else if (a == "-av") {
            const double r = Number(a), g = Number(a), b = Number(a);
            if (r != 0 || g != 0 || b != 0)
                Warning("-av: an ambient value belongs to no daylight coefficient (ignored)");
        } else {
            return false;
        }
        return true;
    }

    void Formats(const std::string &a) {
        const auto format = [&](char c) {
            const std::optional<DataFormat> f = FormatFromLetter(c, false);
            if (!f) ErrorExit(a + ": unknown format (a, f or d)");
            return *f;
        };
        o_.in = format(a[2]);
        o_.out = format(a.size() == 4 ? a[3] : a[2]);
    }

    RtraceDcOptions &o_;
};

// -Dm: a source named solarK gives coefficient K-1 (DAYSIM reads the number after the name's
// first five characters, whatever they are).
int ModifierCoefficient(const std::string &name) {
    if (name.size() <= 5) return -1;
    return static_cast<int>(std::strtol(name.c_str() + 5, nullptr, 10)) - 1;
}

std::vector<TrackedModifier> Tracked(const RtraceDcOptions &o, const FlatScene &flat) {
    std::vector<TrackedModifier> tracked;
    for (const std::string &name : LightSources(flat)) {
        TrackedModifier t;
        t.name = name;
        t.context_of = tracked.empty() ? -1 : 0;
        if (o.by_direction) {
            t.bin_expression = "dspatch";
            t.nbins = o.coefficients;
        } else {
            const int k = ModifierCoefficient(name);
            if (k < 0 || k >= o.coefficients) {
                Warning("light source '" + name + "' " +
                        (k < 0 ? "is not named solarK (K from 1)"
                               : "is coefficient " + std::to_string(k + 1) + " of only " +
                                     std::to_string(o.coefficients) + " (-N)") +
                        ": its light is in no coefficient");
                continue;
            }
            t.first_column = k;
        }
        tracked.push_back(t);
    }
    if (tracked.empty()) Warning("no light source gives a coefficient: every coefficient is 0");
    return tracked;
}

std::string Header(const RtraceDcOptions &o, const std::vector<std::string> &args,
                   const std::string &octree_header) {
    std::string h = "#?RADIANCE\n" + octree_header;
    for (size_t k = 0; k < args.size(); ++k) h += (k ? " " : "") + args[k];
    h += "\n";
    if (o.out != DataFormat::Ascii) h += "FORMAT=" + std::string(FormatName(o.out)) + "\n";
    return h + "\n";
}

// Whether sensor `index` is an irradiance sensor (-U, else -I).
bool Irradiance(const RtraceDcOptions &o, uint64_t index) {
    if (o.sensor_units.empty()) return o.trace.contrib.irradiance;
    if (index >= o.sensor_units.size())
        ErrorExit("input ray " + std::to_string(index + 1) + ": -U gives units for only " +
                  std::to_string(o.sensor_units.size()) + " sensors");
    return o.sensor_units[index] == 1;
}

class Writer {
  public:
    Writer(const RtraceDcOptions &o, OutputFile *out) : o_(o), out_(*out) {}

    // One sensor's coefficients: the red part of record's first N columns over -L.
    void Put(const double *record, int columns) {
        line_.clear();
        values_.assign(o_.coefficients, 0.0);
        for (int k = 0; k < std::min(columns, o_.coefficients); ++k)
            values_[k] = record[3 * k] / o_.source_luminance;
        if (o_.out == DataFormat::Ascii) {
            char buf[32];
            for (double v : values_) {
                std::snprintf(buf, sizeof buf, "%e\t", v);
                line_ += buf;
            }
            line_ += '\n';
            out_.Write(line_);
        } else if (o_.out == DataFormat::Float) {
            std::vector<float> f(values_.begin(), values_.end());
            out_.Write(f.data(), f.size() * sizeof(float));
        } else {
            out_.Write(values_.data(), values_.size() * sizeof(double));
        }
    }

  private:
    const RtraceDcOptions &o_;
    OutputFile &out_;
    std::string line_;
    std::vector<double> values_;
};

}  // namespace

RtraceDcOptions ParseRtraceDcOptions(const std::vector<std::string> &args,
                                     std::vector<std::string> *header_args) {
    RtraceDcOptions o;
    std::vector<std::string> expanded = ExpandOptionFiles(args);
    expanded.insert(expanded.begin(), args.empty() ? "rtrace_dc-gpu" : args[0]);
    Parser parser(expanded, &o);
    const std::vector<std::string> pass = parser.Run();
    o.cache = parser.Cache();
    const bool irradiance = o.trace.contrib.irradiance;
    std::vector<std::string> unused;
    o.trace = ParseRcontribOptions(pass, &unused);
    o.trace.contrib.irradiance = irradiance;
    // (with a positive -lr, rtrace_dc -aa 0 -lr 6 -lw 0.004 -ad 1000 finds no sky, as DAYSIM's
    // does)
    if (o.cache.accuracy > 0) WeighAsWithCache(&o.trace.contrib);
    o.trace.modifiers.clear();
    o.trace.cal.push_back(CalCommand{false, kDaysimPatchCal});
    *header_args = expanded;
    return o;
}

size_t RunRtraceDc(const RtraceDcOptions &o, const std::vector<std::string> &header_args,
                   const std::string &rays_spec, OutputFile *given_out) {
    const std::unique_ptr<tbb::global_control> threads = LimitThreads(o.trace.threads);
    std::string octree_header;
    const FlatScene flat = ReadRcontribScene(o.trace.scene, &octree_header);
    const std::vector<TrackedModifier> tracked = Tracked(o, flat);
    LightEngines engines(o.trace, o.cache, o.report_cache, flat, tracked);
    int columns = 0;
    for (const TrackedModifier &t : tracked) columns = std::max(columns, t.first_column + t.nbins);

    std::unique_ptr<OutputFile> own_out;
    if (!given_out) own_out = std::make_unique<OutputFile>("-");
    OutputFile &out = given_out ? *given_out : *own_out;
    if (o.header) out.Write(Header(o, header_args, octree_header));
    Writer writer(o, &out);
    ReadSpec spec;
    spec.header = false;
    spec.format = o.in;
    spec.ncols = 1;
    spec.ncomp = 6;
    MatrixReader in(InputSource::Open(rays_spec), spec);

    const StopOnSignals stop;
    constexpr size_t kChunk = 16384;  // sensors traced between writes (a cache: per 4096)
    std::vector<double> rays, records;
    uint64_t first = 0;
    bool more = true;
    while (more) {
        rays.clear();
        double ray[6];
        while (rays.size() < 6 * kChunk && (more = in.ReadRow(ray))) {
            CheckInputRay(ray, first + rays.size() / 6 + 1);
            rays.insert(rays.end(), ray, ray + 6);
            if (ray[3] == 0 && ray[4] == 0 && ray[5] == 0) break;  // flushes, as in rtrace
        }
        if (rays.empty()) break;
        if (StopOnSignals::Requested()) throw Interrupted(StopOnSignals::Requested(), "stopped");
        engines.Trace(
            rays, first, columns, [&o](uint64_t k) { return Irradiance(o, k); }, &records);
        const size_t n = rays.size() / 6;
        records.resize(n * 3 * static_cast<size_t>(std::max(columns, 1)), 0.0);
        for (size_t i = 0; i < n; ++i) writer.Put(&records[i * 3 * std::max(columns, 1)], columns);
        std::fflush(out.Stream());
        first += n;
    }
    if (own_out) own_out->Commit();
    engines.Finish();
    return first;
}

}  // namespace dayflux
