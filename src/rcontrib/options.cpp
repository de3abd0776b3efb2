#include "rcontrib/options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <tuple>

#include "rcontrib/rtrace_like.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/options.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux {

namespace {

// The columns of a record, all modifiers' bins together (r1000's 144 million fit; ints index
// them on both engines).
constexpr int kMaxBins = 1 << 28;

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-n nprocs][-V][-c count][-fo][-r][-e expr][-f source][-o ospec][-p "
              "p1=V1,p2=V2][-b binv][-bn N]"
              " {-m mod | -M file} [rtrace options] [-seed N][-asub N][-backend name][-device "
              "name][-progress][-no_commands] octree   (or: " +
              prog + " -devices)");
}

// Applies "a=1,b=2" (separators , : ;) to a context, as RADIANCE's set_eparams().
void ApplyParams(cal::Context &cx, const std::string &params) {
    std::string p = params;
    for (char &c : p)
        if (c == ',' || c == ':' || c == ';') c = ';';
    if (!p.empty()) cx.Load(p, FileLoc{"-p", 0});
}

// RADIANCE's boolean options: -x toggles, -x+ -x1 -xy -xt set, anything else clears.
bool Flag(const std::string &a, bool current) {
    if (a.size() == 2) return !current;
    return a[2] == '+' || a[2] == '1' || a[2] == 'y' || a[2] == 't';
}

// The index of value among an option's choices (an enum's order), or an error naming them.
template <typename Enum>
Enum Choice(const std::string &option, const std::string &value,
            std::initializer_list<const char *> choices) {
    const int n = static_cast<int>(choices.size());
    int k = 0;
    std::string names;
    for (const char *c : choices) {
        if (value == c) return static_cast<Enum>(k);
        names += std::string(k == 0 ? "" : k == n - 1 ? " or " : ", ") + c;
        ++k;
    }
    ErrorExit(option + " " + value + ": " + names);
}

GpuTraversal Traversal(const std::string &option, const std::string &t) {
    return Choice<GpuTraversal>(option, t, {"auto", "rayquery", "bvh"});
}

std::string Environment(const char *name) {
    const char *v = std::getenv(name);
    return v ? v : "";
}

// The options in order, one group of them per function, each saying whether it took `a`.
class Parser : public OptionCursor {
  public:
    Parser(std::vector<std::string> args, RcontribOptions *o)
        : OptionCursor(std::move(args)), o_(*o) {
        o_.engine.device = Environment("DAYFLUX_VULKAN_DEVICE");
        if (const std::string t = Environment("DAYFLUX_GPU_TRAVERSAL"); !t.empty())
            o_.engine.traversal = Traversal("DAYFLUX_GPU_TRAVERSAL=", t);
    }

    // Parses the options; returns the index of the first scene argument.
    size_t Run(const char *prog, std::vector<std::string> *args_for_header) {
        for (; i_ < args_.size(); ++i_) {
            const std::string a = args_[i_];
            if (a.empty() || a[0] != '-' || a.size() == 1) break;
            const size_t start = i_;
            if (!Ours(a) && !Modifiers(a) && !Formats(a) && !Records(a) && !Tracing(a)) {
                std::fprintf(stderr, "%s: unknown option '%s'\n", prog, a.c_str());
                Usage(prog);
            }
            for (size_t k = start; k <= i_; ++k) args_for_header->push_back(args_[k]);
        }
        // RADIANCE applies -o to the modifiers after it, so one after the last is silently lost.
        if (ospec_after_last_modifier_)
            Warning("-o " + ospec_ + " after the last modifier has no effect (put it before -m)");
        // -backend, else vulkan where -device names one, else DAYFLUX_BACKEND, else embree.
        const std::string env_backend = Environment("DAYFLUX_BACKEND");
        o_.engine.backend = !backend_.empty()      ? backend_
                            : device_named_        ? "vulkan"
                            : !env_backend.empty() ? env_backend
                                                   : "embree";
        return i_;
    }

  private:
    // addmodifier(): -bn is evaluated now, with what is defined so far (the value remembered for
    // the modifiers after it, since -M may name thousands); a name may be tracked once.
    void AddModifier(const std::string &name) {
        if (!names_.insert(name).second) ErrorExit("duplicate modifier '" + name + "'");
        auto [it, added] = bin_counts_.emplace(std::make_tuple(o_.cal.size(), params_, bn_), 0);
        if (added) {
            auto cx = MakeCalContext(o_, params_);
            const double n = cx->Compile(bn_, FileLoc{"-bn", 0}).Evaluate(*cx);
            // Checked as a double: int() of NaN or of 1e14 (-e MF:1000000) is undefined.
            if (!(n + .5 >= 1))
                ErrorExit("-bn " + bn_ + ": bin count " + FormatNumber(n) + " is below 1");
            if (!(n + .5 < kMaxBins + 1.))
                ErrorExit("-bn " + bn_ + ": bin count " + FormatNumber(n) + " is above " +
                          std::to_string(kMaxBins) + " (more than a record can hold)");
            it->second = static_cast<int>(n + .5);
        }
        ModifierSpec m;
        m.tracked.name = name;
        m.tracked.bin_expression = binv_;
        m.tracked.nbins = it->second;
        m.params = params_;
        m.output = ospec_;
        ospec_after_last_modifier_ = false;
        o_.modifiers.push_back(m);
    }

    // -m -M -b -bn -p -e -f: the tracked modifiers and their calcomp definitions.
    bool Modifiers(const std::string &a) {
        if (a == "-m") {
            AddModifier(Value(a));
        } else if (a == "-M") {
            const std::string file = Value(a);
            std::ifstream f(FindOnRaypath(file));
            if (!f) ErrorExit("-M: cannot open modifier file '" + file + "'");
            for (std::string w; f >> w;) AddModifier(w);
        } else if (a == "-b") {
            binv_ = Value(a);
        } else if (a == "-bn") {
            bn_ = Value(a);
        } else if (a == "-p") {
            params_ = Value(a);
        } else if (a == "-e") {
            o_.cal.push_back({false, Value(a)});
        } else if (a == "-f") {
            o_.cal.push_back({true, Value(a)});
        } else {
            return false;
        }
        return true;
    }

    // -f[adf][adfc] (input and output formats), -fo, -h.
    bool Formats(const std::string &a) {
        if (a.rfind("-fo", 0) == 0) {
            o_.force_open = Flag(a.substr(0, 1) + a.substr(2), o_.force_open);
        } else if (a[1] == 'f' && a.size() >= 3) {
            const auto format = [&](char c, bool output) {
                const std::optional<DataFormat> f = FormatFromLetter(c, output);
                if (!f) ErrorExit("bad format option '" + a + "'");
                return *f;
            };
            o_.in = format(a[2], false);
            o_.out = a.size() > 3 ? format(a[3], true) : o_.in;
        } else if (a.rfind("-h", 0) == 0) {
            o_.header = Flag(a, o_.header);
        } else {
            return false;
        }
        return true;
    }

    // -o -c -x -y -n -r -t -w: where records go, how many rays make one, progress.
    bool Records(const std::string &a) {
        if (a == "-o") {
            ospec_ = Value(a);  // for the modifiers after it, as in RADIANCE
            ospec_after_last_modifier_ = true;
        } else if (a.rfind("-w", 0) == 0) {
            // warnings on or off: ours are few and always shown
        } else if (a.rfind("-r", 0) == 0 && a.size() <= 3) {
            o_.recover = Flag(a, o_.recover);
        } else if (a == "-c") {
            o_.accumulate = Integer(a);
        } else if (a == "-x") {
            o_.xres = Integer(a);
        } else if (a == "-y") {
            o_.yres = Integer(a);
        } else if (a == "-n") {
            o_.threads = Integer(a);
        } else if (a == "-t") {
            o_.report_seconds = Number(a);
        } else {
            return false;
        }
        return true;
    }

    // rtrace's options that rcontrib takes, and those it forces.
    bool Tracing(const std::string &a) {
        ContribOptions &c = o_.contrib;
        if (a == "-ab") {
            c.ambient_bounces = Integer(a);
        } else if (a == "-ad") {
            c.ambient_divisions = Integer(a);
        } else if (a == "-lw") {
            c.limit_weight = Number(a);
            // (RADIANCE takes a negative weight into the hemisphere's count of samples: the
            // root of a negative number)
            if (!(c.limit_weight >= 0))
                ErrorExit("-lw " + FormatNumber(c.limit_weight) + ": a weight of 0 or more");
        } else if (a == "-lr") {
            c.limit_reflections = Integer(a);
        } else if (a == "-st") {
            c.specular_threshold = Number(a);
        } else if (a == "-ss") {
            c.specular_jitter = Number(a);
        } else if (a == "-dj") {
            c.source_jitter = Number(a);
            // (RADIANCE trims the jitter's square by the root of 1 - frac^2 / 2: NaN directions
            // beyond the root of 2)
            if (!(c.source_jitter >= 0 && c.source_jitter <= 1))
                ErrorExit("-dj " + FormatNumber(c.source_jitter) + ": a fraction from 0 to 1");
        } else if (a == "-ds") {
            c.source_size_ratio = Number(a);
        } else if (a == "-dr") {
            c.direct_relays = Integer(a);
        } else if (a.rfind("-V", 0) == 0) {
            c.contributions = Flag(a, c.contributions);
        } else if (a.rfind("-I", 0) == 0) {
            c.irradiance = Flag(a, c.irradiance);
        } else if (a.rfind("-i", 0) == 0) {
            c.first_hit_irradiance = Flag(a, c.first_hit_irradiance);
        } else if (a.rfind("-ld", 0) == 0) {
            // vwrays -d gives -ld- unless the view clips behind (-va): rays as long as their
            // direction vectors, which the engines do not limit yet (docs/compat.md).
            if (RtraceFlag(a, false))  // (-ld alone toggles: on)
                ErrorExit(a + ": rays limited to their length are not supported");
        } else if (a.rfind("-u", 0) == 0 || a.rfind("-bv", 0) == 0) {
            // random/back-face flags: our sampling is always repeatable for a given -seed
        } else if (a == "-ar") {
            // rcontrib has no cache; -sensor_cache (ours) takes it as rtrace does
            o_.ambient_resolution = Integer(a);
        } else if (a == "-aa" || a == "-as" || a == "-dt" || a == "-aw" || a == "-dc" ||
                   a == "-dp") {
            // forced by rcontrib (-aa 0 -as 0 -dt 0, making -dc moot), or the pretest of
            // virtual sources (-dp), which we do not need (docs/compat.md)
            Value(a);
        } else if (a == "-av") {
            Value(a), Value(a), Value(a);
        } else {
            return false;
        }
        return true;
    }

    // Ours: -seed -first_record -asub -backend -device -gpu_traversal -gpu_accum -gpu_cal
    // -gpu_engine -gpu_waves -gpu_spirv_opt -gpu_scratch -se -progress -no_commands.
    bool Ours(const std::string &a) {
        if (a == "-asub") {
            // N x N samples in each cell of the first ambient hemisphere, one of them
            // continuing its diffuse paths (docs/compat.md).
            o_.contrib.ambient_subsamples = Integer(a);
            if (o_.contrib.ambient_subsamples < 1) ErrorExit("-asub: a whole number of 1 or more");
        } else if (a == "-sensor_cache") {
            o_.sensor_cache = Number(a);
            if (!(o_.sensor_cache >= 0 && o_.sensor_cache < 10))
                ErrorExit("-sensor_cache: an accuracy (as -aa) of 0 or more");
        } else if (a == "-target_error") {
            o_.target_error = Number(a);
            if (!(o_.target_error > 0 && o_.target_error < 1))
                ErrorExit("-target_error: a relative error between 0 and 1 (0.02 for 2 %)");
        } else if (a == "-max_samples") {
            o_.max_samples = Integer(a);
            if (o_.max_samples < 8) ErrorExit("-max_samples: at least 8");
        } else if (a == "-target_sky") {
            o_.target_sky = Value(a);
        } else if (a == "-target_report") {
            o_.target_report = Value(a);
        } else if (a == "-seed") {
            const std::string w = Value(a);
            const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), o_.contrib.seed);
            if (ec != std::errc() || end != w.data() + w.size())
                ErrorExit("-seed " + w + ": a whole number from 0 to 18446744073709551615");
        } else if (a == "-first_record") {
            const double n = Number(a);
            if (!(n >= 0 && n <= 1e15) || n != std::floor(n))
                ErrorExit("-first_record: a whole number of 0 or more");
            o_.first_record = static_cast<long>(n);
        } else if (a == "-backend") {
            backend_ = Value(a);
        } else if (a == "-gpu_accum") {  // the GPU's per-task accumulators
            o_.engine.accumulators = Choice<GpuAccum>(a, Value(a), {"pair", "float", "double"});
        } else if (a == "-gpu_spirv_opt") {  // spirv-opt's level for the GPU's shader
            o_.engine.spirv_opt =
                Choice<GpuSpirvOpt>(a, Value(a), {"auto", "performance", "size", "none"});
        } else if (a == "-gpu_engine") {  // how the GPU shares out the run
            o_.engine.gpu_engine = Choice<GpuEngine>(a, Value(a), {"tasks", "paths"});
        } else if (a == "-gpu_waves") {  // the paths engine's waves before its walk
            o_.engine.gpu_waves = Integer(a);
            // (each wave two dispatches in one submission: a display GPU's watchdog may end a
            // submission of seconds)
            if (o_.engine.gpu_waves < 0 || o_.engine.gpu_waves > 10000)
                ErrorExit("-gpu_waves: a whole number from 0 to 10000");
        } else if (a == "-gpu_cal") {  // the GPU's bins and patterns
            o_.engine.gpu_double_cal = Choice<int>(a, Value(a), {"float", "double"}) == 1;
        } else if (a == "-gpu_scratch") {
            o_.engine.scratch = Choice<GpuScratch>(a, Value(a), {"auto", "on", "off"});
        } else if (a == "-gpu_traversal") {
            o_.engine.traversal = Traversal(a, Value(a));
        } else if (a == "-device") {
            // The Vulkan device(s), by name or index; it implies -backend vulkan and is the
            // way to run on lavapipe.
            o_.engine.device = Value(a);
            device_named_ = true;
        } else if (a == "-se") {
            o_.stderr_file = Value(a);
        } else if (a.rfind("-progress", 0) == 0) {
            o_.progress = Flag(a.substr(0, 2) + a.substr(9), o_.progress);
        } else if (a == "-no_commands") {
            AllowCommandsInDataFiles(false);  // the scene is read after the options
        } else {
            return false;
        }
        return true;
    }

    RcontribOptions &o_;
    std::string binv_ = "0", bn_ = "1", params_, ospec_;
    bool ospec_after_last_modifier_ = false;
    std::map<std::tuple<size_t, std::string, std::string>, int> bin_counts_;
    std::set<std::string> names_;
    std::string backend_;
    bool device_named_ = false;
};

}  // namespace

RcontribOptions ParseRcontribOptions(int argc, char **argv,
                                     std::vector<std::string> *args_for_header) {
    std::vector<std::string> args(argv, argv + argc);
    return ParseRcontribOptions(args, args_for_header);
}

RcontribOptions ParseRcontribOptions(const std::vector<std::string> &args,
                                     std::vector<std::string> *args_for_header) {
    RcontribOptions o;
    const std::vector<std::string> expanded = ExpandOptionFiles(args);
    const char *prog = args.empty() ? "rcontrib-gpu" : args[0].c_str();
    Parser parser(expanded, &o);
    for (size_t i = parser.Run(prog, args_for_header); i < expanded.size(); ++i)
        o.scene.push_back(expanded[i]);
    if (o.scene.empty()) Usage(prog);
    if (o.modifiers.empty()) ErrorExit("no modifiers given (-m or -M)");
    if (o.accumulate < 0) ErrorExit("-c must not be negative");
    if (o.sensor_cache > 0 && (!o.contrib.irradiance || o.accumulate != 1))
        ErrorExit("-sensor_cache: for sensors (-I+), one ray a record (-c 1)");
    if (o.sensor_cache > 0 && !o.stderr_file.empty())
        ErrorExit("-sensor_cache with -se: the replicas would interpolate differently");
    // Sensors share records within the blocks of one input: a shard or a recovered run would
    // group them otherwise, and not merge into the whole run's matrix.
    if (o.sensor_cache > 0 && (o.first_record >= 0 || o.recover))
        ErrorExit(
            "-sensor_cache with -first_record or -r: shards would share records otherwise "
            "than the whole run");
    if (o.target_error > 0 && o.sensor_cache > 0)
        ErrorExit("-target_error with -sensor_cache: not yet");
    if (o.target_error <= 0 && (o.max_samples || !o.target_sky.empty() || !o.target_report.empty()))
        ErrorExit("-max_samples, -target_sky and -target_report go with -target_error");
    if (o.target_error > 0 && !o.max_samples)
        o.max_samples = std::max(8, o.contrib.ambient_divisions);
    if (o.first_record >= 0 && o.accumulate == 0)
        ErrorExit("-first_record with -c 0: one record of every ray cannot be split into shards");
    int64_t col = 0;
    for (ModifierSpec &m : o.modifiers) {
        m.tracked.first_column = static_cast<int>(col);
        col += m.tracked.nbins;
        if (col > kMaxBins)
            ErrorExit("the modifiers' bins, " + std::to_string(col) + " by '" + m.tracked.name +
                      "', are above " + std::to_string(kMaxBins) +
                      " (more columns than a record can hold)");
    }
    // (-target_error's passes estimate the errors themselves, with divisions of their own)
    if (!o.stderr_file.empty() && o.target_error <= 0)
        o.contrib.ambient_divisions = std::max(1, o.contrib.ambient_divisions / kReplicas);
    return o;
}

bool IsEngineOption(const std::string &option) {
    static const std::set<std::string> names = {"-backend",    "-device",      "-gpu_traversal",
                                                "-gpu_accum",  "-gpu_cal",     "-gpu_spirv_opt",
                                                "-gpu_engine", "-gpu_scratch", "-gpu_waves"};
    return names.count(option) > 0;
}

std::unique_ptr<cal::Context> MakeCalContext(const RcontribOptions &o, const std::string &params) {
    auto cx = std::make_unique<cal::Context>();
    cx->LoadRayInit();
    for (const CalCommand &c : o.cal) {
        if (c.file)
            cx->LoadFile(FindOnRaypath(c.text));
        else
            cx->Load(c.text, FileLoc{"-e", 0});
    }
    ApplyParams(*cx, params);
    return cx;
}

std::vector<TrackedModifier> TrackedModifiers(const RcontribOptions &o) {
    std::vector<TrackedModifier> tracked;
    std::map<std::string, int> first_with_params;
    for (const ModifierSpec &m : o.modifiers) {
        tracked.push_back(m.tracked);
        const int k = static_cast<int>(tracked.size()) - 1;
        const int first = first_with_params.emplace(m.params, k).first->second;
        if (first != k) tracked.back().context_of = first;
    }
    return tracked;
}

}  // namespace dayflux
