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
// Placeholder for the modifiers, which are the scene's light sources, known once it is read.
constexpr const char *kPlaceholderModifier = "rtrace_dc-light-sources";

[[noreturn]] void Usage(const std::string &prog) {
    ErrorExit("usage: " + prog +
              " [rtrace options] -N n [-Dm|-Dd] [-L lum] [-U n u1 .. un] -oc octree < rays");
}

bool Flag(const std::string &a, bool current) {
    const char last = a.back();
    if (last == '+') return true;
    if (last == '-') return false;
    return !current;
}

class Parser : public OptionCursor {
  public:
    Parser(std::vector<std::string> args, RtraceDcOptions *o)
        : OptionCursor(std::move(args)), o_(*o) {}

    // The options rtrace_dc reads itself; the rest (rendering and ours) for rcontrib's parser,
    // after rtrace's defaults where they differ from rcontrib's.
    std::vector<std::string> Run() {
        const std::string prog = args_.empty() ? "rtrace_dc-gpu" : args_[0];
        std::vector<std::string> pass = {prog,  "-dj", "0",   "-dr",  "2",   "-st",  "0.15",
                                         "-ab", "0",   "-ad", "1024", "-lw", "2e-3", "-lr",
                                         "-10", "-ds", "0.2", "-ss",  "1"};
        for (i_ = 1; i_ < args_.size(); ++i_) {
            const std::string a = args_[i_];
            if (a.size() < 2 || a[0] != '-') break;
            if (Daysim(a) || Rtrace(a)) continue;
            // Rendering options and ours, for rcontrib's parser (which checks their values);
            // nothing else, so that no value is taken for a scene file.
            static const std::set<std::string> with_value = {
                "-ab",      "-ad",        "-lw",          "-lr",
                "-st",      "-ss",        "-dj",          "-ds",
                "-dr",      "-n",         "-asub",        "-seed",
                "-backend", "-gpu_accum", "-gpu_scratch", "-gpu_traversal",
                "-device"};
            const bool flag = a.rfind("-i", 0) == 0 || a.rfind("-u", 0) == 0 ||
                              a.rfind("-bv", 0) == 0 || a.rfind("-ld", 0) == 0 ||
                              a.rfind("-w", 0) == 0 || a.rfind("-progress", 0) == 0 ||
                              a == "-no_commands";
            if (a == "-sj") {  // DAYSIM's Windows gen_dc passes the specular jitter so
                pass.insert(pass.end(), {"-ss", Value(a)});
            } else if (with_value.count(a)) {
                pass.push_back(a);
                pass.push_back(Value(a));
            } else if (flag && a.size() <= 10) {
                pass.push_back(a);
            } else {
                ErrorExit("unknown option '" + a + "'");
            }
        }
        pass.insert(pass.end(), {"-V+", "-m", kPlaceholderModifier});
        if (i_ >= args_.size()) Usage(prog);
        for (; i_ < args_.size(); ++i_) pass.push_back(args_[i_]);
        if (o_.coefficients < 1) ErrorExit("-N: the number of daylight coefficients is missing");
        return pass;
    }

  private:
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

    // rtrace's own options (not rcontrib's), and those with no effect here.
    bool Rtrace(const std::string &a) {
        if (a.rfind("-o", 0) == 0) {
            if (a != "-oc") ErrorExit(a + ": rtrace_dc writes daylight coefficients only (-oc)");
        } else if (a.rfind("-h", 0) == 0) {
            o_.header = Flag(a, o_.header);
        } else if (a.rfind("-f", 0) == 0 && a.size() >= 3 && a.size() <= 4) {
            Formats(a);
        } else if (a.rfind("-I", 0) == 0) {
            o_.trace.contrib.irradiance = Flag(a, o_.trace.contrib.irradiance);
        } else if (a == "-cache_report") {
            o_.report_cache = true;
        } else if (a == "-aa") {
            o_.ambient_accuracy = Number(a);
        } else if (a == "-ar") {
            o_.ambient_resolution = Integer(a);
        } else if (a == "-as") {
            o_.ambient_supersamples = Integer(a);
        } else if (a == "-x" || a == "-y" || a == "-dt" || a == "-dc" || a == "-dp" || a == "-aw") {
            // -x/-y shape pictures, which rtrace_dc does not write; every source is tested for
            // shadow (as -dt 0, which -dc then does not affect); virtual sources need no pretest.
            Number(a);
        } else if (a.rfind("-dv", 0) == 0) {
            if (!Flag(a, true)) ErrorExit(a + ": invisible light sources are not supported");
        } else if (a == "-av") {
            const double r = Number(a), g = Number(a), b = Number(a);
            if (r != 0 || g != 0 || b != 0)
                Warning("-av: an ambient value belongs to no daylight coefficient (ignored)");
        } else if (a == "-me" || a == "-ma") {
            const double r = Number(a), g = Number(a), b = Number(a);
            if (r != 0 || g != 0 || b != 0)
                ErrorExit(a + ": participating media are not supported");
        } else if (a == "-mg" || a == "-ms") {
            if (Number(a) != 0 && a == "-mg")
                ErrorExit(a + ": participating media are not supported");
        } else if (a == "-ae" || a == "-ai" || a == "-aE" || a == "-aI" || a == "-af" ||
                   a == "-e" || a == "-ap" || a.rfind("-P", 0) == 0 || a.rfind("-t", 0) == 0) {
            ErrorExit(a + ": not supported by rtrace_dc-gpu");
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

// The scene's light sources (light, glow, illum, spotlight materials), by name.
std::vector<std::string> LightSources(const FlatScene &flat) {
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (const Primitive &p : flat.scene.objects) {
        if (p.type != "light" && p.type != "glow" && p.type != "illum" && p.type != "spotlight")
            continue;
        if (seen.insert(p.name).second) names.push_back(p.name);
    }
    return names;
}

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

// The engines a run needs: one with -I+ and one without, as the sensors' units ask.
class Engines {
  public:
    Engines(const RtraceDcOptions &o, const FlatScene &flat,
            const std::vector<TrackedModifier> &tracked)
        : o_(o), flat_(flat), tracked_(tracked) {}

    // With -aa above 0, irradiance sensors go through the sensor cache
    // (raytrace/sensor_cache.h), rtrace's ambient cache at the sensors.
    ContribEngine *For(bool irradiance) {
        std::unique_ptr<ContribEngine> &e = engines_[irradiance];
        if (!e) {
            e = Create(irradiance, false);
            if (irradiance && o_.ambient_accuracy > 0 && o_.trace.contrib.ambient_bounces > 0) {
                SensorCacheOptions c;
                c.accuracy = o_.ambient_accuracy;
                c.resolution = o_.ambient_resolution;
                c.seed = o_.trace.contrib.seed;
                e = WithSensorCache(std::move(e), Create(true, true), flat_, c, o_.report_cache);
            }
        }
        return e.get();
    }

  private:
    // direct_only: -ab 0 (the sensor cache's direct light).
    std::unique_ptr<ContribEngine> Create(bool irradiance, bool direct_only) const {
        ContribOptions c = o_.trace.contrib;
        c.irradiance = irradiance;
        c.contributions = true;
        if (direct_only) c.ambient_bounces = 0;
        return CreateContribEngine(
            flat_, c, tracked_, [this](int) { return MakeCalContext(o_.trace, ""); },
            o_.trace.engine);
    }

    const RtraceDcOptions &o_;
    const FlatScene &flat_;
    const std::vector<TrackedModifier> &tracked_;
    std::unique_ptr<ContribEngine> engines_[2];
};

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

// Traces rays (6 doubles each; sensor numbers from first) into records, in runs of sensors of
// one unit and at most the engine's batch, in parallel.
void TraceChunk(const RtraceDcOptions &o, Engines &engines, const std::vector<double> &rays,
                uint64_t first, int columns, std::vector<double> *records) {
    const size_t n = rays.size() / 6, width = 3 * static_cast<size_t>(columns);
    records->assign(n * width, 0.0);
    struct Run {
        size_t begin, end;
        ContribEngine *engine;
    };
    std::vector<Run> runs;
    for (size_t i = 0; i < n; ++i) {
        const bool zero = rays[6 * i + 3] == 0 && rays[6 * i + 4] == 0 && rays[6 * i + 5] == 0;
        if (zero) continue;  // rtrace's bogus ray: a line of zeros
        const bool irradiance = Irradiance(o, first + i);
        ContribEngine *e = engines.For(irradiance);
        if (!runs.empty() && runs.back().engine == e && runs.back().end == i &&
            runs.back().end - runs.back().begin < e->BatchRays())
            ++runs.back().end;
        else
            runs.push_back({i, i + 1, e});
    }
    tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
        const Run &run = runs[r];
        run.engine->Trace(&rays[6 * run.begin], run.end - run.begin, first + run.begin, 0,
                          records->data() + run.begin * width);
    });
}

}  // namespace

RtraceDcOptions ParseRtraceDcOptions(const std::vector<std::string> &args,
                                     std::vector<std::string> *header_args) {
    RtraceDcOptions o;
    std::vector<std::string> expanded = ExpandOptionFiles(args);
    expanded.insert(expanded.begin(), args.empty() ? "rtrace_dc-gpu" : args[0]);
    Parser parser(expanded, &o);
    const std::vector<std::string> pass = parser.Run();
    const bool irradiance = o.trace.contrib.irradiance;
    std::vector<std::string> unused;
    o.trace = ParseRcontribOptions(pass, &unused);
    o.trace.contrib.irradiance = irradiance;
    // With the ambient cache (-aa > 0) rtrace weighs an ambient sample by the surface's
    // reflectance alone, so -lw cuts only deep, dim paths; rcontrib's estimator, which traces
    // here, also divides a sample's weight by the sample count, and -lw would cut every ambient
    // ray (with a positive -lr: rtrace_dc -aa 0 -lr 6 -lw 0.004 -ad 1000 finds no sky, as
    // DAYSIM's does) or play roulette with them. So -lw is taken per sample (-lw / -ad) and a
    // positive -lr becomes Russian roulette to that depth (docs/compat.md).
    if (o.ambient_accuracy > 0) {
        ContribOptions &c = o.trace.contrib;
        c.limit_weight /= std::max(1, c.ambient_divisions);
        if (c.limit_reflections > 0) c.limit_reflections = -c.limit_reflections;
    }
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
    Engines engines(o, flat, tracked);
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
        if (!tracked.empty()) TraceChunk(o, engines, rays, first, columns, &records);
        const size_t n = rays.size() / 6;
        records.resize(n * 3 * static_cast<size_t>(std::max(columns, 1)), 0.0);
        for (size_t i = 0; i < n; ++i) writer.Put(&records[i * 3 * std::max(columns, 1)], columns);
        std::fflush(out.Stream());
        first += n;
    }
    if (own_out) own_out->Commit();
    return first;
}

}  // namespace dayflux
