// rcontrib-gpu: RADIANCE's rcontrib (contribution coefficients of modifiers to input rays), on
// dayflux's ray tracing backends. This version traces on the CPU with Embree and covers the
// daylight-coefficient case: glow sources (skies, windows), distant light sources (suns) sampled
// directly, plastic, metal and trans (pure specular), glass and mirror, -I/-V and the ambient and
// limit options. Options it does not know are errors, as in RADIANCE; options that RADIANCE
// forces in rcontrib (-aa 0 -as 0 -dt 0) are accepted and ignored.
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cal/calcomp.h"
#include "matrix/header.h"
#include "matrix/reader.h"
#include "matrix/rgbe.h"
#include "matrix/writer.h"
#include "raytrace/backend.h"
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
#include "raytrace/vulkan/vulkan_contrib.h"
#endif
#include "raytrace/contrib.h"
#include "scene/flatten.h"
#include "scene/octree.h"
#include "scene/reader.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/pipeline.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux {
namespace {

namespace fs = std::filesystem;

struct CalCommand {
    bool file;  // -f file, else -e expression
    std::string text;
};

struct ModifierSpec {
    TrackedModifier tracked;
    std::string params;  // -p in force
};

struct Options {
    ContribOptions contrib;
    std::vector<CalCommand> cal;
    std::vector<ModifierSpec> modifiers;
    DataFormat in = DataFormat::Ascii, out = DataFormat::Ascii;
    bool header = true;
    int accumulate = 1;  // -c
    int xres = 0, yres = 0;
    int threads = 0;
    double report_seconds = 0;  // -t: RADIANCE's progress report every so many seconds
    std::string stderr_file;    // -se (ours): standard errors of the entries, as a matrix
    bool progress = false;      // -progress: a progress line with the time left (ours)
    std::string ospec;          // -o: empty for the standard output
    bool force_open = false;    // -fo: overwrite existing output files
    bool recover = false;       // -r: continue the records of existing output files
    std::string backend;
    bool gpu_float = false;  // -gpu_accum float
    std::vector<std::string> scene;
};

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-n nprocs][-V][-c count][-fo][-r][-e expr][-f source][-o ospec][-p "
              "p1=V1,p2=V2][-b binv][-bn N]"
              " {-m mod | -M file} [rtrace options] [-seed N][-asub N][-backend name][-device "
              "name][-progress] octree");
}

// Applies "a=1,b=2" (separators , : ;) to a context, as RADIANCE's set_eparams().
void ApplyParams(cal::Context &cx, const std::string &params) {
    std::string p = params;
    for (char &c : p)
        if (c == ',' || c == ':' || c == ';') c = ';';
    if (!p.empty()) cx.Load(p, FileLoc{"-p", 0});
}

std::unique_ptr<cal::Context> MakeContext(const Options &o, const std::string &params) {
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

// ofname(): the output name for modifier mod and bin, from a spec with at most one %s (the
// modifier) and one integer conversion (the bin). flags: kByModifier, kByBin.
constexpr int kByModifier = 1, kByBin = 2;
std::string OutputName(const std::string &spec, const std::string &mod, int bin, int *flags) {
    size_t mpos = std::string::npos, bpos = std::string::npos;
    for (size_t i = 0; i < spec.size(); ++i) {
        if (spec[i] != '%') continue;
        do ++i;
        while (i < spec.size() && std::isdigit(static_cast<unsigned char>(spec[i])));
        const char c = i < spec.size() ? spec[i] : '\0';
        if (c == '%') continue;
        if (c == 's' && mpos == std::string::npos)
            mpos = i;
        else if (std::strchr("dioxX", c) && c && bpos == std::string::npos)
            bpos = i;
        else
            ErrorExit("bad output format '" + spec + "'");
    }
    *flags =
        (mpos != std::string::npos ? kByModifier : 0) | (bpos != std::string::npos ? kByBin : 0);
    // The spec was checked above: only digits between % and the conversion.
    std::vector<char> buf(spec.size() + mod.size() + 64);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#pragma GCC diagnostic ignored "-Wformat-security"
    if (*flags == (kByModifier | kByBin) && mpos < bpos)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), mod.c_str(), bin);
    else if (*flags == (kByModifier | kByBin))
        std::snprintf(buf.data(), buf.size(), spec.c_str(), bin, mod.c_str());
    else if (*flags == kByModifier)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), mod.c_str());
    else if (*flags == kByBin)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), bin);
    else if (*flags == 0)
        std::snprintf(buf.data(), buf.size(), "%s", spec.c_str());
#pragma GCC diagnostic pop
    return buf.data();
}

// Progress on stderr: RADIANCE's -t line ("P% done after H hours", only when -y gives the
// total) and our -progress line with the rate and the time left.
class ProgressReport {
  public:
    ProgressReport(double radiance_interval, bool progress, long total)
        : interval_(radiance_interval),
          progress_(progress),
          total_(total),
          start_(Clock::now()),
          last_radiance_(start_),
          last_progress_(start_) {}

    void Update(long done) {
        if (interval_ <= 0 && !progress_) return;
        const auto now = Clock::now();
        const double elapsed = Seconds(now - start_);
        if (interval_ > 0 && total_ > 0 && Seconds(now - last_radiance_) >= interval_) {
            std::fprintf(stderr, "%.2f%% done after %.3f hours\n", 100.0 * done / total_,
                         elapsed / 3600.0);
            last_radiance_ = now;
        }
        if (progress_ && (Seconds(now - last_progress_) >= 1.0 || (total_ > 0 && done == total_))) {
            const double rate = elapsed > 0 ? done / elapsed : 0;
            if (total_ > 0 && rate > 0)
                std::fprintf(
                    stderr,
                    "rcontrib-gpu: %ld of %ld records (%.1f%%), %.0f s, about %.0f s left\n", done,
                    total_, 100.0 * done / total_, elapsed, (total_ - done) / rate);
            else
                std::fprintf(stderr, "rcontrib-gpu: %ld records, %.0f s, %.1f records/s\n", done,
                             elapsed, rate);
            last_progress_ = now;
        }
    }

  private:
    using Clock = std::chrono::steady_clock;
    static double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
    double interval_;
    bool progress_;
    long total_;
    Clock::time_point start_, last_radiance_, last_progress_;
};

// One output: the standard output or a file (command) that -o names, with the columns (bins)
// that go there in order.
struct OutputStream {
    std::string name;
    std::string modifier;
    int bin = 0;
    int flags = 0;
    bool standard_error = false;  // the -se output
    std::vector<int> columns;
    std::unique_ptr<OutputFile> file;
    size_t prefix_bytes = 0;  // -r: the existing file's header (and resolution line)
};

size_t RecordBytes(const Options &o, const OutputStream &s) {
    const size_t n = s.columns.size();
    return o.out == DataFormat::RGBE ? 4 * n : (o.out == DataFormat::Float ? 12 : 24) * n;
}

// Copies the first `bytes` of file `name` to out, in pieces (a recovered output may be large).
void CopyPrefix(const std::string &name, size_t bytes, OutputFile *out) {
    std::ifstream f(name, std::ios::binary);
    std::vector<char> piece(size_t(1) << 22);
    while (bytes > 0) {
        const size_t n = std::min(bytes, piece.size());
        if (!f.read(piece.data(), static_cast<std::streamsize>(n)))
            ErrorExit("cannot read '" + name + "' to recover it");
        out->Write(piece.data(), n);
        bytes -= n;
    }
}

// recover_output(): the number of complete records in every output (-1 if there is nothing to
// recover), after checking that they are files of the format asked for. Sets prefix_bytes.
long RecoverableRecords(const Options &o, std::vector<OutputStream> &outputs) {
    if (o.out == DataFormat::Ascii) ErrorExit("cannot recover ASCII output");
    if (o.accumulate <= 0) ErrorExit("cannot recover with -c 0 (one record of all rays)");
    long last = -1;
    for (OutputStream &s : outputs) {
        if (s.name == "-") ErrorExit("cannot recover from stdout");
        if (s.name[0] == '!') ErrorExit("cannot recover from command");
        std::error_code ec;
        const auto size = fs::file_size(s.name, ec);
        if (ec || size == 0) {
            if (ec) Warning("missing recover file '" + s.name + "'");
            Warning("no previous data to recover");
            return 0;
        }
        std::ifstream f(s.name, std::ios::binary);
        std::string head(std::min<uintmax_t>(size, 1 << 16), '\0');
        f.read(head.data(), static_cast<std::streamsize>(head.size()));
        size_t body = 0;
        if (o.header) {
            const size_t end = head.find("\n\n");
            if (head.rfind("#?RADIANCE", 0) != 0 || end == std::string::npos ||
                head.substr(0, end + 1).find(FormatLine(o.out)) == std::string::npos)
                ErrorExit("format mismatch for '" + s.name + "'");
            body = end + 2;
        }
        if (s.columns.size() == 1 && o.xres > 0 && o.yres > 0) {
            const size_t eol = head.find('\n', body);
            if (eol == std::string::npos ||
                head.substr(body, eol + 1 - body) != ResolutionLine(o.xres, o.yres))
                ErrorExit("resolution mismatch for '" + s.name + "'");
            body = eol + 1;
        }
        s.prefix_bytes = body;
        const long n = static_cast<long>((size - body) / RecordBytes(o, s));
        if (last < 0 || n < last) last = n;
    }
    if (last == 0) Warning("no previous data to recover");
    return std::max(last, 0L);
}

// -se: every input ray is traced as this many independent replicas with -ad / replicas each;
// their mean is the result and their spread gives its standard error.
constexpr int kReplicas = 8;

bool Flag(const std::string &a, bool current) {
    if (a.size() == 2) return !current;
    return a[2] == '+' || a[2] == '1' || a[2] == 'y' || a[2] == 't';
}

Options Parse(int argc, char **argv, std::vector<std::string> *args_for_header) {
    Options o;
    std::string binv = "0", bn = "1", params;
    std::vector<std::string> expanded;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a.size() > 1 && a[0] == '@') {  // options from a file
            std::ifstream f(a.substr(1));
            if (!f) ErrorExit("cannot open option file '" + a.substr(1) + "'");
            std::string w;
            while (f >> w) expanded.push_back(w);
        } else {
            expanded.push_back(a);
        }
    }
    size_t i = 0;
    auto value = [&](const std::string &opt) -> std::string {
        if (i + 1 >= expanded.size()) ErrorExit(opt + ": missing argument");
        return expanded[++i];
    };
    auto number = [&](const std::string &opt) {
        double v;
        std::string w = value(opt);
        if (!ParseNumber(w, &v)) ErrorExit(opt + ": bad number '" + w + "'");
        return v;
    };
    // addmodifier(): -bn is evaluated now, with what is defined so far (the value remembered for
    // the modifiers after it, since -M may name thousands); a name may be tracked once.
    std::map<std::tuple<size_t, std::string, std::string>, int> bin_counts;
    std::set<std::string> names;
    const auto add_modifier = [&](const std::string &name) {
        if (!names.insert(name).second) ErrorExit("duplicate modifier '" + name + "'");
        auto [it, added] = bin_counts.emplace(std::make_tuple(o.cal.size(), params, bn), 0);
        if (added) {
            auto cx = MakeContext(o, params);
            const double n = cx->Compile(bn, FileLoc{"-bn", 0}).Evaluate(*cx);
            it->second = static_cast<int>(n + .5);
            if (it->second < 1)
                ErrorExit("-bn " + bn + ": bin count " + std::to_string(it->second) +
                          " is below 1");
        }
        ModifierSpec m;
        m.tracked.name = name;
        m.tracked.bin_expression = binv;
        m.tracked.nbins = it->second;
        m.params = params;
        o.modifiers.push_back(m);
    };
    for (; i < expanded.size(); ++i) {
        const std::string a = expanded[i];
        if (a.empty() || a[0] != '-' || a.size() == 1) break;
        const size_t start = i;
        if (a == "-m") {
            add_modifier(value(a));
        } else if (a == "-M") {
            const std::string file = value(a);
            std::ifstream f(FindOnRaypath(file));
            if (!f) ErrorExit("-M: cannot open modifier file '" + file + "'");
            std::string w;
            while (f >> w) add_modifier(w);
        } else if (a == "-b") {
            binv = value(a);
        } else if (a == "-bn") {
            bn = value(a);
        } else if (a == "-p") {
            params = value(a);
        } else if (a == "-e") {
            o.cal.push_back({false, value(a)});
        } else if (a == "-f") {
            o.cal.push_back({true, value(a)});
        } else if (a[1] == 'f' && a.size() >= 3) {  // -f[adf][adfc], -fo
            if (a.rfind("-fo", 0) == 0) {
                o.force_open = Flag(a.substr(0, 1) + a.substr(2), o.force_open);
                for (size_t k = start; k <= i; ++k) args_for_header->push_back(expanded[k]);
                continue;
            }
            auto fmt = [&](char c, bool output) {
                switch (c) {
                    case 'a':
                        return DataFormat::Ascii;
                    case 'f':
                        return DataFormat::Float;
                    case 'd':
                        return DataFormat::Double;
                    case 'c':
                        if (output) return DataFormat::RGBE;
                        [[fallthrough]];
                    default:
                        ErrorExit("bad format option '" + a + "'");
                }
            };
            o.in = fmt(a[2], false);
            o.out = a.size() > 3 ? fmt(a[3], true) : o.in;
        } else if (a == "-o") {
            o.ospec = value(a);
        } else if (a.rfind("-w", 0) == 0) {
            // warnings on or off: ours are few and always shown
        } else if (a.rfind("-r", 0) == 0 && a.size() <= 3) {
            o.recover = Flag(a, o.recover);
        } else if (a == "-c") {
            o.accumulate = static_cast<int>(number(a));
        } else if (a == "-x") {
            o.xres = static_cast<int>(number(a));
        } else if (a == "-y") {
            o.yres = static_cast<int>(number(a));
        } else if (a == "-n") {
            o.threads = static_cast<int>(number(a));
        } else if (a == "-ab") {
            o.contrib.ambient_bounces = static_cast<int>(number(a));
        } else if (a == "-ad") {
            o.contrib.ambient_divisions = static_cast<int>(number(a));
        } else if (a == "-lw") {
            o.contrib.limit_weight = number(a);
        } else if (a == "-lr") {
            o.contrib.limit_reflections = static_cast<int>(number(a));
        } else if (a == "-asub") {
            // Ours: N x N samples in each cell of the first ambient hemisphere, one of them
            // continuing its diffuse paths (docs/compat.md).
            o.contrib.ambient_subsamples = static_cast<int>(number(a));
            if (o.contrib.ambient_subsamples < 1) ErrorExit("-asub: a whole number of 1 or more");
        } else if (a == "-seed") {
            o.contrib.seed = static_cast<uint64_t>(number(a));
        } else if (a == "-backend") {
            o.backend = value(a);
        } else if (a == "-gpu_accum") {
            // The GPU's per-task accumulators: double (the default) or float.
            const std::string t = value(a);
            if (t != "float" && t != "double") ErrorExit("-gpu_accum " + t + ": float or double");
            o.gpu_float = t == "float";
        } else if (a == "-gpu_traversal") {
            // How the GPU finds hits: auto (ray queries where the device has them), rayquery,
            // or bvh (our own BVH, for devices without ray queries); as DAYFLUX_GPU_TRAVERSAL.
            const std::string t = value(a);
            if (t != "auto" && t != "rayquery" && t != "bvh")
                ErrorExit("-gpu_traversal " + t + ": auto, rayquery or bvh");
            setenv("DAYFLUX_GPU_TRAVERSAL", t.c_str(), 1);
        } else if (a == "-device") {
            // The Vulkan device, by name or index (as DAYFLUX_VULKAN_DEVICE); it implies
            // -backend vulkan and is the way to run on lavapipe.
            setenv("DAYFLUX_VULKAN_DEVICE", value(a).c_str(), 1);
            if (o.backend.empty()) o.backend = "vulkan";
        } else if (a.rfind("-V", 0) == 0) {
            o.contrib.contributions = Flag(a, o.contrib.contributions);
        } else if (a.rfind("-I", 0) == 0) {
            o.contrib.irradiance = Flag(a, o.contrib.irradiance);
        } else if (a.rfind("-i", 0) == 0) {
            o.contrib.first_hit_irradiance = Flag(a, o.contrib.first_hit_irradiance);
        } else if (a.rfind("-h", 0) == 0) {
            o.header = Flag(a, o.header);
        } else if (a.rfind("-u", 0) == 0 || a.rfind("-bv", 0) == 0) {
            // random/back-face flags: our sampling is always repeatable for a given -seed
        } else if (a == "-st") {
            o.contrib.specular_threshold = number(a);
        } else if (a == "-ss") {
            o.contrib.specular_jitter = number(a);
        } else if (a == "-dj") {
            o.contrib.source_jitter = number(a);
        } else if (a == "-ds") {
            o.contrib.source_size_ratio = number(a);
        } else if (a == "-dr") {
            o.contrib.direct_relays = static_cast<int>(number(a));
        } else if (a == "-aa" || a == "-as" || a == "-dt" || a == "-ar" || a == "-aw" ||
                   a == "-dc" || a == "-dp") {
            // forced by rcontrib (-aa 0 -as 0 -dt 0, making -dc moot), or the pretest of
            // virtual sources (-dp), which we do not need (docs/compat.md)
            value(a);
        } else if (a == "-se") {
            o.stderr_file = value(a);
        } else if (a == "-t") {
            o.report_seconds = number(a);
        } else if (a.rfind("-progress", 0) == 0) {
            o.progress = Flag(a.substr(0, 2) + a.substr(9), o.progress);
        } else if (a == "-av") {
            value(a), value(a), value(a);
        } else {
            std::fprintf(stderr, "%s: unknown option '%s'\n", argv[0], a.c_str());
            Usage(argv[0]);
        }
        for (size_t k = start; k <= i; ++k) args_for_header->push_back(expanded[k]);
    }
    for (; i < expanded.size(); ++i) o.scene.push_back(expanded[i]);
    if (o.scene.empty()) Usage(argv[0]);
    if (o.modifiers.empty()) ErrorExit("no modifiers given (-m or -M)");
    if (o.accumulate < 0) ErrorExit("-c must not be negative");
    int col = 0;
    for (ModifierSpec &m : o.modifiers) m.tracked.first_column = col, col += m.tracked.nbins;
    if (!o.stderr_file.empty())
        o.contrib.ambient_divisions = std::max(1, o.contrib.ambient_divisions / kReplicas);
    return o;
}

int Main(int argc, char **argv) {
    std::vector<std::string> header_args = {argv[0]};
    Options o = Parse(argc, argv, &header_args);
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, o.threads);
    std::string octree_header;
    Scene scene;
    {
        SceneReader reader(&scene);
        for (const std::string &s : o.scene) {
            if (IsOctreeFile(s))
                octree_header += ReadOctree(s, &scene).header;
            else
                reader.ReadFile(s);
        }
    }
    FlatScene flat = Flatten(std::move(scene));
    std::vector<TrackedModifier> tracked;
    std::map<std::string, int> first_with_params;
    for (const ModifierSpec &m : o.modifiers) {
        tracked.push_back(m.tracked);
        const int k = static_cast<int>(tracked.size()) - 1;
        const int first = first_with_params.emplace(m.params, k).first->second;
        if (first != k) tracked.back().context_of = first;
    }
    const auto make_context = [&o](int k) { return MakeContext(o, o.modifiers[k].params); };
    // -backend, else DAYFLUX_BACKEND, else embree. The Vulkan integrator takes the run when it
    // can; otherwise one line says why and Embree does it.
    const std::string backend_name = ChooseBackend(o.backend);
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
    std::unique_ptr<VulkanContribIntegrator> gpu;
    if (backend_name == "vulkan") {
        std::string why;
        gpu = VulkanContribIntegrator::Create(flat, o.contrib, tracked, make_context, o.gpu_float,
                                              &why);
        if (!gpu) Warning("the Vulkan backend cannot take this run (" + why + "); using Embree");
    }
    std::mutex gpu_mutex;
#else
    if (backend_name == "vulkan") Warning("this build has no Vulkan backend; using Embree");
#endif
    // The CPU integrator, with Embree's structures, only where the GPU does not take the run.
    std::unique_ptr<Backend> backend;
    std::unique_ptr<ContribIntegrator> cpu;
    std::string backend_label;
    int ncols = 0;
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
    if (gpu) {
        backend_label = "vulkan: " + gpu->DeviceName();
        ncols = gpu->Columns();
    }
#endif
    if (backend_label.empty()) {
        backend = CreateEmbreeBackend();
        backend->Commit(flat);
        cpu = std::make_unique<ContribIntegrator>(flat, *backend, o.contrib, tracked, make_context);
        backend_label = backend->Name();
        ncols = cpu->Columns();
    }

    // Outputs, in the order RADIANCE opens them: by modifier, then bin.
    std::vector<OutputStream> outputs;
    if (o.ospec.empty()) {
        outputs.emplace_back().name = "-";
        for (int c = 0; c < ncols; ++c) outputs[0].columns.push_back(c);
    } else {
        std::map<std::string, size_t> output_named;
        for (const ModifierSpec &m : o.modifiers)
            for (int b = 0; b < m.tracked.nbins; ++b) {
                int flags = 0;
                const std::string name = OutputName(o.ospec, m.tracked.name, b, &flags);
                auto [it, added] = output_named.emplace(name, outputs.size());
                if (added) {
                    OutputStream &s = outputs.emplace_back();
                    s.name = name, s.modifier = m.tracked.name, s.bin = b, s.flags = flags;
                }
                outputs[it->second].columns.push_back(m.tracked.first_column + b);
            }
        // A file per modifier (-o %s with a sun per modifier) can mean thousands open at once:
        // up to the hard limit, where RADIANCE stops at the soft one (1024 on Debian).
        struct rlimit files;
        if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max &&
            outputs.size() + 64 > files.rlim_cur) {
            files.rlim_cur = files.rlim_max;
            setrlimit(RLIMIT_NOFILE, &files);
        }
    }
    if (!o.stderr_file.empty()) {
        OutputStream &se = outputs.emplace_back();
        se.name = o.stderr_file;
        se.standard_error = true;
        for (int c = 0; c < ncols; ++c) se.columns.push_back(c);
    }
    // -r: the complete records every output already has, kept (header and all) in front of
    // the rest; as many input rays (times -c) are skipped, and the rest keep their random
    // numbers, so a recovered run ends as an uninterrupted one would have.
    long recovered = o.recover ? RecoverableRecords(o, outputs) : 0;
    for (OutputStream &s : outputs) {
        if (!o.recover && s.name != "-" && s.name[0] != '!' && !o.force_open && fs::exists(s.name))
            ErrorExit("cannot open '" + s.name + "' for writing: file exists (use -fo+)");
        s.file = std::make_unique<OutputFile>(s.name);
        const int reclen = static_cast<int>(s.columns.size());
        if (recovered > 0) {
            CopyPrefix(s.name, s.prefix_bytes + recovered * RecordBytes(o, s), s.file.get());
            continue;
        }
        if (o.header) {
            std::vector<char *> av;
            for (std::string &a : header_args) av.push_back(a.data());
            std::string h = HeaderStart(static_cast<int>(av.size()), av.data());
            h.insert(h.find('\n') + 1, octree_header);
            h += "SOFTWARE= dayflux rcontrib-gpu (" + backend_label + ")\n" + DateLines() +
                 "NCOMP=3\n";
            if (s.name != "-" && ((s.flags & kByModifier) || reclen == 1))
                h += "MODIFIER=" + s.modifier + "\n";
            if (s.flags & kByBin) h += "BIN=" + std::to_string(s.bin) + "\n";
            if (o.yres > 0) h += "NROWS=" + std::to_string(o.yres * std::max(o.xres, 1)) + "\n";
            if (o.xres <= 0 || reclen > 1) h += "NCOLS=" + std::to_string(reclen) + "\n";
            if (o.out == DataFormat::Float || o.out == DataFormat::Double)
                h += NativeBigEndian() ? "BigEndian=1\n" : "BigEndian=0\n";
            h += FormatLine(o.out) + "\n";
            s.file->Write(h);
        }
        if (reclen == 1 && o.xres > 0 && o.yres > 0) s.file->Write(ResolutionLine(o.xres, o.yres));
    }
    // Input rays: origin and direction, in blocks; each block traced in parallel, written in order.
    ReadSpec rs;
    rs.header = false;
    rs.format = o.in;
    rs.ncols = 1;
    rs.ncomp = 6;
    MatrixReader in(InputSource::Open("-"), rs);
    // Rays go through in chunks traced in parallel; a chunk holds the pieces (segments) of the
    // records it touches, so -c 0 or -c 10000 still uses every thread. Records end after -c rays
    // or, partial, at the end of input.
    const int accumulate = o.accumulate;
    // Small chunks for the CPU (one sensor ray can cost millions of rays); the GPU takes many
    // rays per dispatch, within a bound on the records' memory.
    size_t chunk_rays = 2;
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
    if (gpu)
        chunk_rays =
            std::clamp<size_t>((size_t(64) << 20) / (24 * static_cast<size_t>(ncols)), 1, 4096);
#endif
    struct Segment {
        size_t first = 0, count = 0;  // rays of the chunk
        bool ends_record = false;
        double scale = 1;  // 1/-c, applied when the record ends
    };
    struct Block {
        std::vector<double> rays;  // 6 per ray; a zero direction is a flush, not traced
        uint64_t first_ray = 0;
        std::vector<Segment> segments;
        std::vector<std::vector<double>> sums;  // per segment
        std::vector<std::vector<double>> vars;  // per segment, with -se: variance of the sums
        bool flush = false;                     // a zero ray: flush the outputs after
    };
    uint64_t next_ray = 0;
    bool done = false, warned_dummy = false;
    const long wanted = o.yres > 0 ? static_cast<long>(o.yres) * std::max(o.xres, 1) : -1;
    long ended = 0, written = 0;  // records ended by the reader, records written
    if (recovered > 0) {
        if (wanted >= 0 && recovered >= wanted) {
            Warning("output appears to be complete");
            for (OutputStream &s : outputs) s.file->Commit();
            return 0;
        }
        const long skip = recovered * std::max(accumulate, 1);
        double ray[6];
        for (long k = 0; k < skip; ++k)
            if (!in.ReadRow(ray)) ErrorExit("unexpected EOF on input");
        next_ray = static_cast<uint64_t>(skip);
        ended = written = recovered;
    }
    long in_record = 0;  // rays in the record being read
    std::vector<double> pending(3 * static_cast<size_t>(ncols), 0.0);
    std::vector<double> pending_var(pending.size(), 0.0), standard_error(pending.size());
    const bool replicate = !o.stderr_file.empty();
    std::vector<double> part;
    std::vector<std::string> text(outputs.size());
    ProgressReport progress(o.report_seconds, o.progress, wanted);
    OrderedPipeline<Block>(
        [&]() -> std::unique_ptr<Block> {
            if (done) return nullptr;
            auto b = std::make_unique<Block>();
            b->first_ray = next_ray;
            auto add_ray = [&](const double *ray) {
                const size_t n = b->rays.size() / 6;
                b->rays.insert(b->rays.end(), ray, ray + 6);
                if (b->segments.empty() || b->segments.back().ends_record)
                    b->segments.push_back(Segment{n, 0, false, 1});
                ++b->segments.back().count;
            };
            auto end_record = [&](double scale) {
                if (b->segments.empty() || b->segments.back().ends_record)
                    b->segments.push_back(Segment{b->rays.size() / 6, 0, false, 1});
                b->segments.back().ends_record = true;
                b->segments.back().scale = scale;
                in_record = 0;
                ++ended;
            };
            double ray[6];
            while (b->rays.size() / 6 < chunk_rays) {
                if (wanted >= 0 && ended >= wanted) {
                    done = true;
                    break;
                }
                if (!in.ReadRow(ray)) {
                    if (accumulate <= 0) {
                        end_record(1);  // -c 0: one record of every ray
                    } else if (in_record > 0) {
                        Warning("partial accumulation in final record");
                        end_record(accumulate > 1 ? 1.0 / static_cast<double>(in_record) : 1);
                    }
                    done = true;
                    break;
                }
                const bool zero = ray[3] == 0 && ray[4] == 0 && ray[5] == 0;
                if (zero && accumulate <= 0) {
                    if (!warned_dummy) Warning("dummy ray(s) ignored during accumulation");
                    warned_dummy = true;
                    continue;
                }
                // A zero ray counts as a ray that contributes nothing and flushes the output (a
                // caller feeding rays through a pipe uses it to get results so far).
                add_ray(ray);
                b->flush = b->flush || zero;
                ++in_record;
                if (accumulate > 0 && in_record == accumulate)
                    end_record(accumulate > 1 ? 1.0 / accumulate : 1);
            }
            if (b->segments.empty()) return nullptr;
            next_ray += b->rays.size() / 6;
            return b;
        },
        [&](Block &b) {
            const size_t n = 3 * static_cast<size_t>(ncols);
            b.sums.resize(b.segments.size());
            b.vars.resize(replicate ? b.segments.size() : 0);
            std::vector<double> one, sq;
#ifdef DAYFLUX_HAVE_GPU_CONTRIB
            if (gpu) {  // the whole block in one go (per replica with -se), then per segment
                // One block at a time on the device, its records allocated only then.
                std::lock_guard<std::mutex> lock(gpu_mutex);
                const size_t nrays = b.rays.size() / 6;
                const int reps = replicate ? kReplicas : 1;
                std::vector<std::vector<double>> rec(reps, std::vector<double>(nrays * n, 0.0));
                for (int k = 0; k < reps; ++k)
                    gpu->Trace(b.rays.data(), nrays, b.first_ray, k, rec[k].data());
                for (size_t i = 0; i < b.segments.size(); ++i) {
                    const Segment &seg = b.segments[i];
                    b.sums[i].assign(n, 0.0);
                    if (replicate) b.vars[i].assign(n, 0.0);
                    for (size_t ray = seg.first; ray < seg.first + seg.count; ++ray)
                        for (size_t j = 0; j < n; ++j) {
                            double m = 0, q = 0;
                            for (int k = 0; k < reps; ++k) {
                                const double v = rec[k][ray * n + j];
                                m += v, q += v * v;
                            }
                            m /= reps;
                            b.sums[i][j] += m;
                            if (replicate)
                                b.vars[i][j] +=
                                    std::max(0.0, (q - reps * m * m) / (reps - 1) / reps);
                        }
                }
                return;
            }
#endif
            for (size_t i = 0; i < b.segments.size(); ++i) {
                const Segment &seg = b.segments[i];
                b.sums[i].assign(n, 0.0);
                if (replicate) b.vars[i].assign(n, 0.0);
                for (size_t ray = seg.first; ray < seg.first + seg.count; ++ray) {
                    const double *r = &b.rays[6 * ray];
                    if (r[3] == 0 && r[4] == 0 && r[5] == 0) continue;
                    const uint64_t index = b.first_ray + ray;
                    if (!replicate) {
                        cpu->Trace(r, r + 3, index, b.sums[i].data());
                        continue;
                    }
                    std::vector<double> mean(n, 0.0);
                    sq.assign(n, 0.0);
                    for (int k = 0; k < kReplicas; ++k) {
                        one.assign(n, 0.0);
                        cpu->Trace(r, r + 3, index * kReplicas + k, one.data());
                        for (size_t j = 0; j < n; ++j) mean[j] += one[j], sq[j] += one[j] * one[j];
                    }
                    for (size_t j = 0; j < n; ++j) {
                        const double m = mean[j] / kReplicas;
                        b.sums[i][j] += m;
                        // variance of the mean of the replicas
                        b.vars[i][j] += std::max(
                            0.0, (sq[j] - kReplicas * m * m) / (kReplicas - 1) / kReplicas);
                    }
                }
            }
        },
        [&](Block &b) {
            for (size_t i = 0; i < b.segments.size(); ++i) {
                for (size_t k = 0; k < pending.size(); ++k) pending[k] += b.sums[i][k];
                if (replicate)
                    for (size_t k = 0; k < pending.size(); ++k) pending_var[k] += b.vars[i][k];
                if (!b.segments[i].ends_record) continue;
                const double scale = b.segments[i].scale;
                if (scale != 1)
                    for (double &v : pending) v *= scale;
                for (size_t k = 0; k < pending.size(); ++k)
                    standard_error[k] = std::sqrt(pending_var[k]) * scale;
                for (size_t s = 0; s < outputs.size(); ++s) {
                    const std::vector<double> &values =
                        outputs[s].standard_error ? standard_error : pending;
                    text[s].clear();
                    if (o.out == DataFormat::Ascii) {
                        for (int c : outputs[s].columns)
                            for (int k = 0; k < 3; ++k) {
                                AppendScientific(&text[s], values[3 * c + k], 6);
                                text[s] += '\t';
                            }
                        text[s] += '\n';
                    } else if (o.out == DataFormat::RGBE) {
                        // RGBE as rcontrib writes it: one flat 4-byte colour per entry, so a
                        // one-column output with -x and -y is a picture.
                        for (int c : outputs[s].columns) {
                            const Colr colr =
                                ToColr(values[3 * c], values[3 * c + 1], values[3 * c + 2]);
                            text[s].append(reinterpret_cast<const char *>(colr.data()), 4);
                        }
                    } else {
                        part.clear();
                        for (int c : outputs[s].columns)
                            part.insert(part.end(), &values[3 * c], &values[3 * c + 3]);
                        RowFormatter(o.out, static_cast<int>(outputs[s].columns.size()), 3)
                            .Append(part.data(), &text[s]);
                    }
                    outputs[s].file->Write(text[s]);
                }
                std::fill(pending.begin(), pending.end(), 0.0);
                std::fill(pending_var.begin(), pending_var.end(), 0.0);
                ++written;
                progress.Update(written);
            }
            if (b.flush)
                for (OutputStream &s : outputs) std::fflush(s.file->Stream());
        });
    if (wanted > 0 && written < wanted)
        ErrorExit("unexpected end of input: " + std::to_string(written) + " of " +
                  std::to_string(wanted) + " records");
    for (OutputStream &s : outputs) s.file->Commit();
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
