#include "rcontrib/rtrace_like.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "matrix/matrices.h"
#include "raytrace/sensor_cache.h"
#include "util/errors.h"
#include "util/files.h"

namespace dayflux {

const char *const kLightSourcesPlaceholder = "rtrace-light-sources";

bool RtraceFlag(const std::string &a, bool current) {
    const char last = a.back();
    if (last == '+' || last == '1' || last == 'y' || last == 'Y' || last == 't' || last == 'T')
        return true;
    if (last == '-' || last == '0' || last == 'n' || last == 'N' || last == 'f' || last == 'F')
        return false;
    return !current;
}

std::vector<std::string> RtraceDefaults(const std::string &program) {
    return {program, "-dj", "0",    "-dr", "2",   "-st", "0.15", "-ab", "0", "-ad",
            "1024",  "-lw", "2e-3", "-lr", "-10", "-ds", "0.2",  "-ss", "1"};
}

std::string RtraceLikeParser::Program() const {
    return std::filesystem::path(args_[0]).filename().string();
}

std::vector<std::string> RtraceLikeParser::Run() {
    std::vector<std::string> &pass = pass_;
    pass = RtraceDefaults(Program());
    for (i_ = 1; i_ < args_.size(); ++i_) {
        const std::string a = args_[i_];
        if (a.size() < 2 || a[0] != '-') break;
        if (Own(a) || Ignored(a)) continue;
        // Rendering options and ours, for rcontrib's parser (which checks their values);
        // nothing else, so that no value is taken for a scene file.
        static const std::set<std::string> with_value = {
            "-ab",           "-ad",          "-lw",         "-lr",
            "-st",           "-ss",          "-dj",         "-ds",
            "-dr",           "-n",           "-asub",       "-seed",
            "-target_error", "-max_samples", "-target_sky", "-target_report"};
        const bool flag = a.rfind("-i", 0) == 0 || a.rfind("-I", 0) == 0 || a.rfind("-u", 0) == 0 ||
                          a.rfind("-bv", 0) == 0 || a.rfind("-ld", 0) == 0 ||
                          a.rfind("-w", 0) == 0 || a.rfind("-progress", 0) == 0 ||
                          a == "-no_commands";
        if (with_value.count(a) || IsEngineOption(a)) {
            pass.push_back(a);
            pass.push_back(Value(a));
        } else if (a.size() <= 4 && (a[1] == 'I' || a[1] == 'i' || a.rfind("-ld", 0) == 0)) {
            // rtrace's booleans (-I -I+ -IT -I0 ...), passed as rcontrib's parser reads them
            const std::string name = a.substr(0, a[1] == 'l' ? 3 : 2);
            if (a.size() > name.size() + 1) ErrorExit("unknown option '" + a + "'");
            bool &value = flags_[name];
            value = RtraceFlag(a, value);
            pass.push_back(name + (value ? "+" : "-"));
        } else if (flag && a.size() <= 10) {
            pass.push_back(a);
        } else {
            ErrorExit("unknown option '" + a + "'");
        }
    }
    pass.insert(pass.end(), {"-V+", "-m", kLightSourcesPlaceholder});
    if (i_ >= args_.size()) Usage();
    for (; i_ < args_.size(); ++i_) pass.push_back(args_[i_]);
    return pass;
}

// rtrace's options that the engines do not take: the ambient cache's (kept for the sensor
// cache), those with no effect here, and those refused.
bool RtraceLikeParser::Ignored(const std::string &a) {
    if (a == "-aa") {
        cache_.accuracy = Number(a);
    } else if (a == "-ar") {
        cache_.resolution = Integer(a);
    } else if (a == "-as") {
        cache_.supersamples = Integer(a);
    } else if (a == "-dt" || a == "-dc" || a == "-dp" || a == "-aw") {
        // Every source is tested for shadow (as -dt 0, which -dc then does not affect);
        // virtual sources need no pretest; there is no cache file to weigh -av in.
        Number(a);
    } else if (a.rfind("-dv", 0) == 0) {
        if (!RtraceFlag(a, true)) ErrorExit(a + ": invisible light sources are not supported");
    } else if (a == "-av") {
        const double r = Number(a), g = Number(a), b = Number(a);
        if (r != 0 || g != 0 || b != 0)
            ErrorExit("-av: an ambient value is not supported (the light is traced, -ab)");
    } else if (a == "-me" || a == "-ma") {
        const double r = Number(a), g = Number(a), b = Number(a);
        if (r != 0 || g != 0 || b != 0) ErrorExit(a + ": participating media are not supported");
    } else if (a == "-mg" || a == "-ms") {
        if (Number(a) != 0 && a == "-mg") ErrorExit(a + ": participating media are not supported");
    } else if (a == "-ae" || a == "-ai" || a == "-aE" || a == "-aI" || a == "-af" || a == "-ap" ||
               a.rfind("-P", 0) == 0 || (a.rfind("-t", 0) == 0 && a.size() <= 3)) {
        ErrorExit(a + ": not supported by " + Program());
    } else {
        return false;
    }
    return true;
}

void WeighAsWithCache(ContribOptions *c) {
    c->limit_weight /= std::max(1, c->ambient_divisions);
    if (c->limit_reflections > 0) c->limit_reflections = -c->limit_reflections;
}

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

TargetErrorOptions TargetErrorOf(const RcontribOptions &o) {
    TargetErrorOptions t;
    t.target = o.target_error;
    t.max_samples = o.max_samples;
    if (!o.target_sky.empty()) {
        const Matrix sky = LoadMatrix(o.target_sky);
        for (int r = 0; r < sky.rows; ++r)
            for (int c = 0; c < sky.cols; ++c) {
                const double red = sky.at(r, c, 0), green = sky.ncomp > 1 ? sky.at(r, c, 1) : red,
                             blue = sky.ncomp > 2 ? sky.at(r, c, 2) : red;
                t.weights.push_back(0.265 * red + 0.670 * green + 0.065 * blue);
            }
    }
    return t;
}

void ReportTargetError(const RcontribOptions &o, const TargetErrorOptions &t,
                       const TargetErrorReport &report) {
    std::fprintf(stderr, "%s: %s\n", ProgramName().c_str(), report.Summary(t).c_str());
    if (o.target_report.empty()) return;
    OutputFile out(o.target_report);
    out.Write("# sensor samples relative_standard_error (-target_error)\n");
    char line[96];
    for (const TargetErrorReport::Ray &r : report.Rays()) {
        std::snprintf(line, sizeof line, "%llu %d %.6g\n", static_cast<unsigned long long>(r.index),
                      r.samples, r.error);
        out.Write(line);
    }
    out.Commit();
}

LightEngines::LightEngines(const RcontribOptions &trace, const AmbientCacheOptions &cache,
                           bool report_cache, const FlatScene &flat,
                           const std::vector<TrackedModifier> &tracked)
    : trace_(trace), cache_(cache), report_cache_(report_cache), flat_(flat), tracked_(tracked) {
    if (trace.target_error > 0) {
        if (cache.accuracy > 0 && trace.contrib.ambient_bounces > 0)
            ErrorExit("-target_error traces every sensor (-aa 0), without the ambient cache");
        target_ = TargetErrorOf(trace);
        report_ = std::make_shared<TargetErrorReport>();
    }
}

void LightEngines::Finish() const {
    if (report_) ReportTargetError(trace_, target_, *report_);
}

ContribEngine *LightEngines::For(bool irradiance) {
    std::unique_ptr<ContribEngine> &e = engines_[irradiance];
    if (!e && report_) {
        TargetErrorOptions target = target_;
        target.sensors = irradiance;
        e = WithTargetError(
            [this, irradiance](int divisions) { return Create(irradiance, false, divisions); },
            target, report_);
        return e.get();
    }
    if (!e) {
        e = Create(irradiance, false);
        if (irradiance && cache_.accuracy > 0 && trace_.contrib.ambient_bounces > 0) {
            SensorCacheOptions c;
            c.accuracy = cache_.accuracy;
            c.resolution = cache_.resolution;
            c.seed = trace_.contrib.seed;
            e = WithSensorCache(std::move(e), Create(true, true), flat_, c, report_cache_);
        }
    }
    return e.get();
}

// direct_only: -ab 0 (the sensor cache's direct light).
std::unique_ptr<ContribEngine> LightEngines::Create(bool irradiance, bool direct_only,
                                                    int divisions) const {
    ContribOptions c = trace_.contrib;
    if (divisions > 0) c.ambient_divisions = divisions;
    c.irradiance = irradiance;
    c.contributions = true;
    if (direct_only) c.ambient_bounces = 0;
    return CreateContribEngine(
        flat_, c, tracked_, [this](int) { return MakeCalContext(trace_, ""); }, trace_.engine);
}

void LightEngines::Trace(const std::vector<double> &rays, uint64_t first, int columns,
                         const std::function<bool(uint64_t)> &irradiance,
                         std::vector<double> *records) {
    const size_t n = rays.size() / 6, width = 3 * static_cast<size_t>(columns);
    records->assign(n * width, 0.0);
    if (tracked_.empty()) return;
    struct Run {
        size_t begin, end;
        ContribEngine *engine;
    };
    std::vector<Run> runs;
    for (size_t i = 0; i < n; ++i) {
        const bool zero = rays[6 * i + 3] == 0 && rays[6 * i + 4] == 0 && rays[6 * i + 5] == 0;
        if (zero) continue;  // rtrace's bogus ray: a line of zeros
        ContribEngine *e = For(irradiance(first + i));
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

}  // namespace dayflux
