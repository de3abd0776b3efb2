// The programs end to end (issue 41): a small scene, sensors and rcontrib-gpu's options are made
// from the input (structure-aware: every byte choosing among materials, surfaces, options and
// numbers, RADIANCE's own and extreme ones), and the run goes through rcontrib-gpu's own code in
// process: its option parser, the scene reader, the materials' table, the engine (Embree), the
// records and the outputs. A UserError is bad input reported as it should be. Findings, besides
// crashes and sanitizer reports: a record missing from the output, or a NaN or infinity in one
// (every input number is finite, and colours are kept below 1e6 so that -V+ cannot overflow; a
// specularity above 1, which the reader warns of, may grow a path to infinity); and where the
// values are finite, -target_error's slices of the same rays (TraceSlices) that do not add up to
// them.
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "rcontrib/options.h"
#include "rcontrib/records.h"
#include "rcontrib/run.h"
#include "scene/flatten.h"

namespace dayflux::fuzz {
namespace {

// The input read as choices: each call takes bytes from the front (zeros once it is used up).
class Choices {
  public:
    Choices(const uint8_t *data, size_t size) : p_(data), end_(data + size) {}
    unsigned Byte() { return p_ < end_ ? *p_++ : 0; }
    // A whole number in [0, n).
    unsigned Below(unsigned n) { return n <= 256 ? Byte() % n : (Byte() << 8 | Byte()) % n; }
    bool Maybe() { return Byte() & 1; }
    template <class T, size_t N>
    const T &Pick(const T (&menu)[N]) {
        return menu[Below(N)];
    }
    // A number as scenes and options hold them: mostly small ones, a sixth from the edges.
    double Number() {
        static const double kEdges[] = {0,     1,      -1,    .5,   2,     1e-6,   1e6,  1e30,
                                        -1e30, 1e-300, 1e300, 180,  360,   1.52,   .99,  3,
                                        1e12,  -1e12,  1e9,   4e-5, 1e-12, 65536., 1e15, -.5};
        const unsigned kind = Below(6);
        if (kind == 0) return Pick(kEdges);
        return (static_cast<int>(Byte()) - 128) / 16.0;  // [-8, 8) in sixteenths
    }
    double Coordinate() { return (static_cast<int>(Byte()) - 128) / 32.0; }  // [-4, 4)
    double Colour() {  // reflectances, and now and then a bright or negative one
        const unsigned kind = Below(8);
        if (kind == 0) return Pick(kColourEdges);
        return Byte() / 255.0;
    }
    std::string Num() { return Text(Number()); }
    std::string Coord() { return Text(Coordinate()); }
    std::string Col() { return Text(Colour()); }
    static std::string Text(double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.9g", v);
        return buf;
    }

  private:
    static constexpr double kColourEdges[] = {0, 1, 100, 1e5, -1, 1e-30};
    const uint8_t *p_, *end_;
};

// Expressions for mixfuncs, brightfuncs and bins: RADIANCE's and ones that reach the library's
// domain errors, infinity, huge and negative values (without blanks: they are string arguments).
const char *const kExpressions[] = {".5",      "Dz",          "sqrt(Dz)",         "if(Dx,1,0)",
                                    "log(Dz)", "1e300*Dz*10", "asin(2*Dy)",       "Dz^.5",
                                    "1/Dz",    "-Dz",         "select(Dx*3,1,2)", "arg(1)"};

// Words joined by blanks. The draws are made in a braced list, which C++ evaluates in order (the
// operands of + it does not): the same input makes the same scene with every compiler, so the
// corpus replays under GCC as it was found under clang.
std::string Words(std::initializer_list<std::string> words) {
    std::string s;
    for (const std::string &w : words) s += (s.empty() ? "" : " ") + w;
    return s;
}

std::string Triple(Choices &in, std::string (Choices::*num)()) {
    return Words({(in.*num)(), (in.*num)(), (in.*num)()});
}

// One material (or pattern and material) named name, its modifiers from those before it.
// *amplifies is set where it is a plastic, metal or trans of specularity above 1 (the reader
// warns): its specular paths may grow a hundredfold a bounce, to infinity where nothing ends
// them (-lr 0 in a bubble), as RADIANCE's never end.
std::string Material(Choices &in, const std::string &name, const std::vector<std::string> &before,
                     const std::string &bsdf, bool *amplifies) {
    const auto any_before = [&] {
        return before.empty() ? "void" : before[in.Below(before.size())];
    };
    const std::string other = any_before();
    const std::string rgb = Triple(in, &Choices::Col);
    const auto specularity = [&] {  // (drawn where in.Col() was: the same scene for an input)
        const double v = in.Colour();
        *amplifies |= v > 1;
        return Choices::Text(v);
    };
    switch (in.Below(15)) {
        case 0:
            return Words({"void plastic", name, "0 0 5", rgb, specularity(), in.Num()});
        case 1:
            return Words({"void metal", name, "0 0 5", rgb, specularity(), in.Num()});
        case 2:
            return Words(
                {"void trans", name, "0 0 7", rgb, specularity(), in.Num(), in.Col(), in.Col()});
        case 3:
            if (in.Maybe()) return Words({"void glass", name, "0 0 3", rgb});
            return Words({"void glass", name, "0 0 4", rgb, in.Num()});
        case 4:
            return Words({"void dielectric", name, "0 0 5", rgb, in.Num(), in.Num()});
        case 5:
            return Words({"void mirror", name, in.Maybe() ? "1 " + other : "0", "0 3", rgb});
        case 6:
            return Words({"void glow", name, "0 0 4", rgb, in.Num()});
        case 7:
            return Words({"void light", name, "0 0 3", rgb});
        case 8:
            return Words({"void illum", name, in.Maybe() ? "1 " + other : "0", "0 3", rgb});
        case 9:
            return Words(
                {"void spotlight", name, "0 0 7", rgb, in.Num(), Triple(in, &Choices::Num)});
        case 10:
            return Words(
                {"void mixfunc", name, "4", other, any_before(), in.Pick(kExpressions), ". 0 0"});
        case 11:  // a pattern on a plastic
            return Words({"void brightfunc", name + "_p", "2", in.Pick(kExpressions),
                          ". 0 0\n" + name + "_p plastic", name, "0 0 5", rgb, "0 0"});
        case 12:
            return Words({"void antimatter", name, "1", other, "0 0"});
        case 13:
            return Words({"void BSDF", name, "6", in.Num(), bsdf, "0 0 1 . 0 0"});
        default:
            return Words({"void aBSDF", name, "5", bsdf, "0 0 1 . 0 0"});
    }
}

// One surface of modifier mod.
std::string Surface(Choices &in, const std::string &mod, int k) {
    const std::string name = "s" + std::to_string(k);
    const std::string p0 = Triple(in, &Choices::Coord), p1 = Triple(in, &Choices::Coord);
    switch (in.Below(9)) {
        default: {
            const unsigned n = 3 + in.Below(3);
            std::string s = Words({mod, "polygon", name, "0 0", std::to_string(3 * n), p0, p1});
            for (unsigned v = 2; v < n; ++v) s += " " + Triple(in, &Choices::Coord);
            return s;
        }
        case 2:
            return Words({mod, in.Maybe() ? "sphere" : "bubble", name, "0 0 4", p0, in.Num()});
        case 3:
            return Words(
                {mod, in.Maybe() ? "cone" : "cup", name, "0 0 8", p0, p1, in.Num(), in.Num()});
        case 4:
            return Words({mod, in.Maybe() ? "cylinder" : "tube", name, "0 0 7", p0, p1, in.Num()});
        case 5:
            return Words({mod, "ring", name, "0 0 8", p0, p1, in.Num(), in.Num()});
        case 6:
            return Words({mod, "source", name, "0 0 4", p0, in.Num()});
    }
}

// The scene: materials m0.., surfaces of them (and of the sky's glow, and void), and a sky.
std::string SceneText(Choices &in, std::vector<std::string> *names, const std::string &bsdf,
                      bool *amplifies) {
    std::string s;
    if (in.Byte() % 4 != 0) {
        s += Words({"void glow skyglow 0 0 4", Triple(in, &Choices::Col), "0\n"});
        s += Words({"skyglow source sky 0 0 4 0 0 1", in.Maybe() ? "180" : in.Num()}) + "\n";
    }
    names->push_back("skyglow");
    const unsigned materials = 1 + in.Below(4);
    for (unsigned m = 0; m < materials; ++m) {
        const std::string name = "m" + std::to_string(m);
        s += Material(in, name, *names, bsdf, amplifies) + "\n";
        names->push_back(name);
    }
    const unsigned surfaces = 1 + in.Below(5);
    for (unsigned k = 0; k < surfaces; ++k) {
        const std::string &mod = (*names)[in.Below(names->size())];
        s += Surface(in, in.Below(8) == 0 ? "void" : mod, static_cast<int>(k)) + "\n";
    }
    return s;
}

// rcontrib-gpu's options: the tracking, and a few of the rest with values ordinary and not.
std::vector<std::string> Options(Choices &in, const std::vector<std::string> &names,
                                 const std::string &output) {
    // Fewer samples than rcontrib's -ad 350 unless the input asks: many runs a second.
    std::vector<std::string> a = {"rcontrib-gpu", "-h-", "-fo+", "-ffd", "-ad", "16"};
    static const char *const kValued[] = {"-ab", "-ad", "-lw", "-lr",   "-st", "-ss",
                                          "-dj", "-ds", "-dr", "-asub", "-c",  "-seed"};
    static const char *const kFlags[] = {"-I+", "-I-", "-i+", "-V+", "-V-", "-u+"};
    const unsigned options = in.Below(6);
    for (unsigned k = 0; k < options; ++k) {
        if (in.Maybe()) {
            a.push_back(in.Pick(kFlags));
            continue;
        }
        a.push_back(in.Pick(kValued));
        const bool small = in.Maybe();
        a.push_back(small ? std::to_string(in.Below(8)) : in.Num());
    }
    switch (in.Below(5)) {
        case 0:
            a.insert(a.end(), {"-e", "MF:" + std::to_string(1 + in.Below(3)), "-f", "reinhart.cal",
                               "-b", "rbin", "-bn", "Nrbins"});
            break;
        case 1:
            a.insert(a.end(), {"-f", "klems_full.cal", "-b", "kbinS", "-bn", "Nkbins", "-e",
                               "kbinS=kbin(0,0,1,0,1,0)"});
            break;
        case 2:
            a.insert(a.end(), {"-b", in.Pick(kExpressions)});
            a.insert(a.end(), {"-bn", std::to_string(1 + in.Below(4))});
            break;
        case 3:
            a.insert(a.end(), {"-bn", in.Num()});
            break;
        default:
            break;
    }
    a.insert(a.end(), {"-o", output});  // for the modifiers after it
    const unsigned tracked = 1 + in.Below(2);
    for (unsigned k = 0; k < tracked; ++k) a.insert(a.end(), {"-m", names[in.Below(names.size())]});
    return a;
}

// The columns of a record: every tracked modifier's bins.
size_t Columns(const RcontribOptions &o) {
    size_t columns = 0;
    for (const ModifierSpec &m : o.modifiers) columns += m.tracked.nbins;
    return columns;
}

// What a run may cost: the fuzzer wants many runs a second, not one deep one.
bool Cheap(const RcontribOptions &o) {
    const ContribOptions &c = o.contrib;
    if (Columns(o) > 20000) return false;  // a record of -bn 1000000 is 24 MB to clear and write
    return c.ambient_bounces <= 4 && c.ambient_divisions <= 512 && c.ambient_subsamples <= 4 &&
           c.specular_jitter <= 16 && c.direct_relays <= 6 && o.accumulate <= 16;
}

struct Scratch {
    ScratchFile scene;
    std::string dir, output;
    bool print = false;  // --print: each input's scene, options, rays and outcome on stderr
};

Scratch *scratch = nullptr;

void RemoveScratch() {
    std::error_code ec;
    if (scratch) std::filesystem::remove_all(scratch->dir, ec);
}

[[noreturn]] void Finding(const std::string &what) {
    std::fprintf(stderr, "engine_fuzzer: %s\n", what.c_str());
    std::abort();
}

// The output holds one record per -c rays (a partial one at the end; one for -c 0), each of
// finite numbers (unless the scene amplifies: Material).
void CheckOutput(const std::string &path, size_t records, size_t columns, bool amplifies) {
    std::ifstream f(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const size_t want = records * columns * 3 * sizeof(double);
    if (bytes.size() != want)
        Finding("the output holds " + std::to_string(bytes.size()) + " bytes, not " +
                std::to_string(want) + " (" + std::to_string(records) + " records of " +
                std::to_string(columns) + " columns)");
    for (size_t i = 0; i < bytes.size() / sizeof(double); ++i) {
        double v;
        std::memcpy(&v, bytes.data() + i * sizeof(double), sizeof v);
        if (!std::isfinite(v) && !amplifies)
            Finding("value " + std::to_string(i) + " of the output is " + std::to_string(v));
    }
}

// -target_error's slices (ContribEngine::TraceSlices: each slice's rows of a sensor's first
// hemisphere and its share of the light sources) add up to the whole trace of the same rays and
// keys, within the sums' rounding.
void CheckSlicesAddUp(const RcontribOptions &o, std::vector<double> rays, int slices) {
    for (size_t r = 0; r < rays.size(); r += 6) CheckInputRay(&rays[r], r / 6 + 1);  // (as read)
    std::string octree_header;
    const FlatScene flat = ReadRcontribScene(o.scene, &octree_header);
    const std::unique_ptr<ContribEngine> engine = CreateRunEngine(o, flat, o.contrib, o.engine);
    const size_t n = rays.size() / 6, width = 3 * static_cast<size_t>(engine->Columns());
    std::vector<uint64_t> keys(n);
    for (size_t i = 0; i < n; ++i) keys[i] = i;
    std::vector<double> whole(width * n, 0.0), apart(width * n * slices, 0.0);
    engine->Trace(rays.data(), n, 0, 0, whole.data());
    if (!engine->TraceSlices(rays.data(), n, keys.data(), 0, slices, apart.data()))
        Finding("the engine has no slices");
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < width; ++j) {
            double sum = 0, size = std::fabs(whole[width * i + j]);
            for (int s = 0; s < slices; ++s) {
                const double v = apart[width * (i * slices + s) + j];
                sum += v;
                size += std::fabs(v);
            }
            // (the tolerance is the slices' size, not their terms': contributions that cancel
            // within a slice could in principle be flagged; none were in 23,000 inputs)
            if (!std::isfinite(sum) || !(std::fabs(sum - whole[width * i + j]) <= 1e-9 * size))
                Finding("ray " + std::to_string(i) + " entry " + std::to_string(j) + ": its " +
                        std::to_string(slices) + " slices add up to " + std::to_string(sum) +
                        ", the whole trace gives " + std::to_string(whole[width * i + j]));
        }
}

// The output's values, exactly, for --print (a change meant to keep the numbers compares them).
void PrintOutput(const std::string &path) {
    std::ifstream f(path, std::ios::binary);
    double v;
    for (size_t i = 0; f.read(reinterpret_cast<char *>(&v), sizeof v); ++i)
        std::fprintf(stderr, "%s%.17g", i % 6 == 0 ? (i ? "\n" : "") : " ", v);
    std::fprintf(stderr, "\n");
}

}  // namespace
}  // namespace dayflux::fuzz

// libFuzzer leaves flags that start with "--" to the target (and replay_main.cpp skips them).
extern "C" int LLVMFuzzerInitialize(int *argc, char ***argv) {
    using namespace dayflux::fuzz;
    scratch = new Scratch;
    for (int i = 1; i < *argc; ++i) scratch->print |= std::strcmp((*argv)[i], "--print") == 0;
    std::string dir = "/tmp/dayflux_engine_fuzz_XXXXXX";
    if (!mkdtemp(dir.data())) Finding("cannot make a scratch folder");
    scratch->dir = dir;
    scratch->output = dir + "/out.mtx";
    std::atexit(RemoveScratch);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    using namespace dayflux;
    using namespace dayflux::fuzz;
    Choices in(data, size);
    std::vector<std::string> names;
    bool amplifies = false;
    const std::string scene = SceneText(in, &names, DAYFLUX_FUZZ_BSDF, &amplifies);
    std::vector<std::string> args = Options(in, names, scratch->output);
    std::vector<double> rays;
    const unsigned nrays = 1 + in.Below(4);
    for (unsigned r = 0; r < nrays; ++r) {
        for (int k = 0; k < 3; ++k) rays.push_back(in.Coordinate());
        for (int k = 0; k < 3; ++k) rays.push_back(in.Maybe() ? in.Coordinate() : in.Number());
    }
    args.insert(args.end(), {"-n", "1", scratch->scene.Write(scene)});
    std::remove(scratch->output.c_str());
    const bool verbose = scratch->print;
    if (verbose) {
        std::fprintf(stderr, "%s", scene.c_str());
        for (const std::string &a : args) std::fprintf(stderr, "%s ", a.c_str());
        std::fprintf(stderr, "\n");
        for (size_t r = 0; r < rays.size(); r += 6)
            std::fprintf(stderr, "ray %.17g %.17g %.17g %.17g %.17g %.17g\n", rays[r], rays[r + 1],
                         rays[r + 2], rays[r + 3], rays[r + 4], rays[r + 5]);
    }
    try {
        std::vector<std::string> header;
        const RcontribOptions o = ParseRcontribOptions(args, &header);
        if (!Cheap(o)) {
            if (verbose) std::fprintf(stderr, "too dear to trace\n");
            return 0;
        }
        size_t next = 0;
        RunRcontrib(o, header, "", [&](double ray[6]) {
            if (next == rays.size()) return false;
            std::memcpy(ray, &rays[next], 6 * sizeof(double));
            next += 6;
            return true;
        });
        const size_t records = o.accumulate <= 0 ? 1 : (nrays + o.accumulate - 1) / o.accumulate;
        CheckOutput(scratch->output, records, Columns(o), amplifies);
        // (its own bytes after the rays', so that the corpus makes the same runs as before)
        const int slices = 2 + static_cast<int>(in.Below(5));
        if (!amplifies) CheckSlicesAddUp(o, rays, slices);
        if (verbose)
            std::fprintf(stderr, "traced %zu records\n", records), PrintOutput(scratch->output);
    } catch (const UserError &e) {  // bad input, reported as it should be
        if (verbose) std::fprintf(stderr, "refused: %s\n", e.what());
    }
    return 0;
}
