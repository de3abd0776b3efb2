#include "rtrace/rtrace.h"

#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>

#include "matrix/header.h"
#include "matrix/rgbe.h"
#include "raytrace/backend.h"
#include "rcontrib/records.h"
#include "rcontrib/run.h"
#include "util/errors.h"
#include "util/signals.h"

namespace dayflux {

namespace {

constexpr double kHuge = 1e10;  // RADIANCE's FHUGE: the length of a ray that meets nothing

[[noreturn]] void Usage(const std::string &prog) {
    ErrorExit("usage: " + prog + " [rtrace options] octree < rays");
}

class Parser : public RtraceLikeParser {
  public:
    Parser(std::vector<std::string> args, RtraceOptions *o)
        : RtraceLikeParser(std::move(args)), o_(*o) {}

  private:
    void Usage() const override { dayflux::Usage(Program()); }

    // rtrace's own options: -o -h -f -x -y -e.
    bool Own(const std::string &a) override {
        if (a.rfind("-o", 0) == 0 && a.size() > 2) {
            o_.outputs = a.substr(2);
        } else if (a.rfind("-h", 0) == 0 && a.size() <= 3) {
            o_.header = RtraceFlag(a, o_.header);
        } else if (a.rfind("-f", 0) == 0 && a.size() >= 3 && a.size() <= 4) {
            Formats(a);
        } else if (a == "-x") {
            o_.xres = Integer(a);
        } else if (a == "-y") {
            o_.yres = Integer(a);
        } else if (a == "-e") {
            o_.error_file = Value(a);
        } else {
            return false;
        }
        return true;
    }

    void Formats(const std::string &a) {
        const auto format = [&](char c, bool output) {
            if (output && c == 'c') return DataFormat::RGBE;
            if (c == 'a') return DataFormat::Ascii;
            if (c == 'f') return DataFormat::Float;
            if (c == 'd') return DataFormat::Double;
            ErrorExit(a + ": unknown format (a, f or d; c for output)");
        };
        o_.in = format(a[2], false);
        o_.out = format(a.size() == 4 ? a[3] : a[2], a.size() == 4);
    }

    RtraceOptions &o_;
};

// The values -o asks for: three numbers each, one, or a name.
int Components(char c) {
    switch (c) {
        case 'o':
        case 'd':
        case 'v':
        case 'V':
        case 'W':
        case 'p':
        case 'n':
        case 'N':
            return 3;
        case 'w':
        case 'l':
        case 'L':
            return 1;
        case 's':
        case 'm':
        case 'M':
        case '~':
            return 0;
        default:
            ErrorExit(std::string("-o: output '") + c +
                      (std::strchr("rRxXcTt", c) ? "' is not supported by rtrace-gpu"
                                                 : "' is not one of rtrace's"));
    }
}

bool NeedsHits(const std::string &outputs) {
    return outputs.find_first_of("lLpnNsmM") != std::string::npos;
}

// What a ray met first, for -o's p n N l L s m M.
struct FirstHit {
    double t = kHuge;
    double point[3] = {0, 0, 0};
    double normal[3] = {0, 0, 0};  // as the surface has it (N)
    double facing[3] = {0, 0, 0};  // turned toward the ray where the material does so (n)
    int object = -1;               // the surface, or the distant source met, or -1
    int modifier = -1;             // its modifier (a mesh triangle's material)
};

class HitFinder {
  public:
    explicit HitFinder(const FlatScene &flat) : flat_(flat), backend_(CreateEmbreeBackend()) {
        backend_->Commit(flat);
    }

    void Find(const double *rays, size_t n, std::vector<FirstHit> *hits) const {
        std::vector<TraceRay> trace(n);
        for (size_t i = 0; i < n; ++i) {
            const double *r = rays + 6 * i;
            trace[i] = TraceRay{{r[0], r[1], r[2]},
                                {r[3], r[4], r[5]},
                                std::numeric_limits<double>::infinity(),
                                -1};
        }
        std::vector<TraceHit> found(n);
        backend_->Closest(trace.data(), found.data(), n);
        hits->assign(n, FirstHit{});
        for (size_t i = 0; i < n; ++i) {
            const double *r = rays + 6 * i;
            if (r[3] == 0 && r[4] == 0 && r[5] == 0) continue;
            FirstHit &h = (*hits)[i];
            for (int k = 0; k < 3; ++k) h.point[k] = r[k];
            if (found[i].hit)
                Surface(found[i], r + 3, &h);
            else
                h.object = DistantSource(r + 3);
            if (h.object >= 0 && h.modifier < 0)
                h.modifier = flat_.scene.objects[h.object].modifier;
        }
    }

  private:
    void Surface(const TraceHit &f, const double *dir, FirstHit *h) const {
        h->t = f.t;
        bool inward = false;
        if (f.shape >= 0) {
            h->object = flat_.shapes[f.shape].object;
            inward = flat_.shapes[f.shape].inward;
        } else {
            h->object = flat_.triangle_object[f.triangle];
            h->modifier = flat_.triangle_material[f.triangle];
        }
        double dot = 0;
        for (int k = 0; k < 3; ++k) {
            h->point[k] = f.point[k];
            // (+ 0.0: a triangle's normal may hold -0 where the polygon's, RADIANCE's, holds 0)
            h->normal[k] = (inward ? -f.normal[k] : f.normal[k]) + 0.0;
            dot += h->normal[k] * dir[k];
        }
        // Materials turn the normal toward the ray (flipsurface()); light sources do not.
        const int mod = h->modifier >= 0 ? h->modifier : flat_.scene.objects[h->object].modifier;
        const Primitive *m = Material(mod);
        const bool light = m && m->info->kind == PrimitiveKind::kLight;
        for (int k = 0; k < 3; ++k) h->facing[k] = dot > 0 && !light ? -h->normal[k] : h->normal[k];
    }

    // sourcehit(): the first distant source (not a glow) whose disc holds the direction, else
    // the first glow's.
    int DistantSource(const double *dir) const {
        int glow = -1;
        for (const AnalyticShape &s : flat_.shapes) {
            if (s.kind != AnalyticShape::kSource) continue;
            const Primitive &p = flat_.scene.objects[s.object];
            const double len = std::sqrt(s.p0[0] * s.p0[0] + s.p0[1] * s.p0[1] + s.p0[2] * s.p0[2]);
            const double cosine = (s.p0[0] * dir[0] + s.p0[1] * dir[1] + s.p0[2] * dir[2]) / len;
            if (!(len > 0) || cosine < std::cos(p.fargs[3] * (M_PI / 360))) continue;
            const Primitive *m = Material(p.modifier);
            if (m && m->type == "glow") {
                if (glow < 0) glow = s.object;
                continue;
            }
            return s.object;
        }
        return glow;
    }

  public:
    // findmaterial(): the modifier chain followed to its material (through aliases).
    const Primitive *Material(int mod) const {
        const std::vector<Primitive> &objs = flat_.scene.objects;
        for (int guard = 0; mod >= 0 && guard < 1000; ++guard) {
            const Primitive &p = objs[mod];
            if (p.info->kind == PrimitiveKind::kMaterial || p.info->kind == PrimitiveKind::kLight)
                return &p;
            if (p.info->kind == PrimitiveKind::kAlias && !p.sargs.empty()) {
                int ref = -1;
                for (int k = mod; k-- > 0 && ref < 0;)
                    if (objs[k].name == p.sargs[0] &&
                        objs[k].info->kind != PrimitiveKind::kSurface &&
                        objs[k].info->kind != PrimitiveKind::kVolume)
                        ref = k;
                if (ref >= 0) {
                    mod = ref;
                    continue;
                }
            }
            mod = p.modifier;
        }
        return nullptr;
    }

  private:
    const FlatScene &flat_;
    std::unique_ptr<Backend> backend_;
};

// Writes the values of one ray at a time in the -f output format.
class ValueWriter {
  public:
    ValueWriter(const RtraceOptions &o, const FlatScene &flat, const HitFinder *hits)
        : o_(o), flat_(flat), hits_(hits) {}

    // ray: as read (origin, unit direction); value: its radiance or irradiance. A zero
    // direction (a flush) writes rtrace's bogus ray: the last ray's origin and direction, a
    // weight of 1 and nothing met.
    void Put(const double *ray, const double *value, const FirstHit *hit, std::string *out) {
        const bool zero = ray[3] == 0 && ray[4] == 0 && ray[5] == 0;
        const bool sensor = o_.trace.contrib.irradiance && !zero;
        double *org = last_origin_, *dir = last_direction_;
        for (int k = 0; k < 3 && !zero; ++k) {
            // rtrace -I traces from just in front of the sensor, back toward it (rtcompute()).
            org[k] = sensor ? ray[k] + 1.1e-4 * ray[3 + k] : ray[k];
            dir[k] = sensor ? -ray[3 + k] : ray[3 + k];
        }
        static const double kZero[3] = {0, 0, 0}, kOne[3] = {1, 1, 1};
        for (char c : o_.outputs) {
            switch (c) {
                case 'o':
                    Numbers(org, 3, out);
                    break;
                case 'd':
                    Numbers(dir, 3, out);
                    break;
                case 'v':
                case 'V':
                    Numbers(value, 3, out);
                    break;
                case 'w':
                    Numbers(kOne, 1, out);
                    break;
                case 'W':
                    Numbers(kOne, 3, out);
                    break;
                case 'l':
                case 'L': {
                    const double t = zero ? kHuge : sensor ? 1e-5 : hit->t;
                    Numbers(&t, 1, out);
                    break;
                }
                case 'p': {
                    double p[3];
                    for (int k = 0; k < 3; ++k)
                        p[k] = sensor ? org[k] + 1e-5 * dir[k] : zero ? org[k] : hit->point[k];
                    Numbers(p, 3, out);
                    break;
                }
                case 'N':
                    Numbers(Surface(hit, sensor) ? hit->normal : kZero, 3, out);
                    break;
                case 'n':
                    Numbers(Surface(hit, sensor) ? hit->facing : kZero, 3, out);
                    break;
                case 's':
                    Name(Met(hit, sensor) ? &flat_.scene.objects[hit->object] : nullptr, out);
                    break;
                case 'm': {
                    const bool met = Met(hit, sensor);
                    *out += !met                ? "*"
                            : hit->modifier < 0 ? "void"
                                                : flat_.scene.objects[hit->modifier].name;
                    *out += '\t';
                    break;
                }
                case 'M': {
                    const bool met = Met(hit, sensor);
                    const Primitive *m = met ? hits_->Material(hit->modifier) : nullptr;
                    *out += !met ? "*" : m ? m->name : "void";
                    *out += '\t';
                    break;
                }
                case '~':
                    *out += "~\t";
                    break;
            }
        }
        if (o_.out == DataFormat::Ascii) *out += '\n';
    }

    // -fc: the value as an RGBE pixel.
    static void Pixel(const double *value, std::string *out) {
        const Colr c = ToColr(value[0], value[1], value[2]);
        out->append(reinterpret_cast<const char *>(c.data()), c.size());
    }

  private:
    static bool Met(const FirstHit *hit, bool sensor) { return !sensor && hit && hit->object >= 0; }
    // A surface met (not a distant source), whose normal is known.
    static bool Surface(const FirstHit *hit, bool sensor) {
        return Met(hit, sensor) && hit->t < kHuge;
    }
    static void Name(const Primitive *p, std::string *out) {
        *out += p ? p->name : "*";
        *out += '\t';
    }
    void Numbers(const double *v, int n, std::string *out) const {
        if (o_.out == DataFormat::Ascii) {
            char buf[40];
            for (int k = 0; k < n; ++k) {
                std::snprintf(buf, sizeof buf, "%e\t", v[k]);
                *out += buf;
            }
        } else if (o_.out == DataFormat::Float) {
            for (int k = 0; k < n; ++k) {
                const float f = static_cast<float>(v[k]);
                out->append(reinterpret_cast<const char *>(&f), sizeof f);
            }
        } else {
            out->append(reinterpret_cast<const char *>(v), n * sizeof(double));
        }
    }

    const RtraceOptions &o_;
    const FlatScene &flat_;
    const HitFinder *hits_;
    double last_origin_[3] = {0, 0, 0}, last_direction_[3] = {0, 0, 0};
};

std::string Header(const RtraceOptions &o, const std::vector<std::string> &args,
                   const std::string &octree_header, const std::string &label) {
    std::string h = "#?RADIANCE\n" + octree_header;
    for (size_t k = 0; k < args.size(); ++k) h += (k ? " " : "") + args[k];
    h += "\nSOFTWARE= dayflux rtrace-gpu (" + label + ")\n" + DateLines();
    int ncomp = 0;
    for (char c : o.outputs) ncomp += Components(c);
    if (ncomp > 0) h += "NCOMP=" + std::to_string(ncomp) + "\n";
    if (o.out == DataFormat::Float || o.out == DataFormat::Double)
        h += NativeBigEndian() ? "BigEndian=1\n" : "BigEndian=0\n";
    return h + FormatLine(o.out) + "\n";
}

void Normalize(double *d) {
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (length > 0)
        for (int k = 0; k < 3; ++k) d[k] /= length;
}

void Write(const std::string &bytes) {
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), stdout) != bytes.size())
        ErrorExit("write error on standard output");
}

}  // namespace

RtraceOptions ParseRtraceOptions(const std::vector<std::string> &args,
                                 std::vector<std::string> *header_args) {
    RtraceOptions o;
    std::vector<std::string> expanded = ExpandOptionFiles(args);
    expanded.insert(expanded.begin(), args.empty() ? "rtrace-gpu" : args[0]);
    Parser parser(expanded, &o);
    const std::vector<std::string> pass = parser.Run();
    o.cache = parser.Cache();
    const RtraceOptions own = o;
    std::vector<std::string> unused;
    o.trace = ParseRcontribOptions(pass, &unused);
    o.trace.in = own.in;
    o.trace.out = own.out;
    if (o.cache.accuracy > 0) WeighAsWithCache(&o.trace.contrib);
    o.trace.modifiers.clear();
    for (char c : o.outputs) Components(c);  // each one known
    if (o.out == DataFormat::RGBE && o.outputs != "v")
        ErrorExit("color format only with -ov (-fc writes each ray's value as a pixel)");
    header_args->assign(expanded.begin(), expanded.end() - static_cast<long>(o.trace.scene.size()));
    return o;
}

void RunRtrace(const RtraceOptions &o, const std::vector<std::string> &header_args) {
    if (!o.error_file.empty() && !std::freopen(o.error_file.c_str(), "a", stderr))
        ErrorExit("cannot open error file '" + o.error_file + "'");
    const std::unique_ptr<tbb::global_control> threads = LimitThreads(o.trace.threads);
    std::string octree_header;
    const FlatScene flat = ReadRcontribScene(o.trace.scene, &octree_header);
    std::vector<TrackedModifier> tracked;
    for (const std::string &name : LightSources(flat)) {
        TrackedModifier t;
        t.name = name;
        t.first_column = static_cast<int>(tracked.size());
        t.context_of = tracked.empty() ? -1 : 0;
        tracked.push_back(t);
    }
    if (tracked.empty()) Warning("no light sources found");
    const int columns = static_cast<int>(tracked.size());
    LightEngines engines(o.trace, o.cache, false, flat, tracked);
    std::optional<HitFinder> hits;
    if (NeedsHits(o.outputs) && !o.trace.contrib.irradiance) hits.emplace(flat);
    ValueWriter writer(o, flat, hits ? &*hits : nullptr);

    if (o.header) {
        const std::string label =
            tracked.empty() ? "no light sources" : engines.For(o.trace.contrib.irradiance)->Label();
        Write(Header(o, header_args, octree_header, label));
    }
    if (o.xres > 0 && o.yres > 0)
        Write("-Y " + std::to_string(o.yres) + " +X " + std::to_string(o.xres) + "\n");
    std::fflush(stdout);

    // -x and -y bound the rays read (rtrace's vcount); -x alone flushes every x rays.
    const long wanted = o.yres > 0 ? static_cast<long>(o.yres) * std::max(o.xres, 1) : -1;
    const size_t flush_every = o.yres <= 0 && o.xres > 0 ? static_cast<size_t>(o.xres) : 0;
    const RaySource rays = StandardInputRays(o.in);
    const StopOnSignals stop;
    constexpr size_t kChunk = 16384;  // rays traced between writes
    std::vector<double> block, records, values;
    std::vector<FirstHit> first_hits;
    std::string bytes;
    uint64_t done = 0;
    bool more = true;
    while (more) {
        block.clear();
        double ray[6];
        while (block.size() < 6 * kChunk) {
            if (wanted >= 0 && static_cast<long>(done + block.size() / 6) >= wanted) {
                more = false;
                break;
            }
            if (!(more = rays(ray))) break;
            CheckInputRay(ray, done + block.size() / 6 + 1);
            Normalize(ray + 3);  // as rtrace's nextray(): lengths and -od are per unit
            block.insert(block.end(), ray, ray + 6);
            if (ray[3] == 0 && ray[4] == 0 && ray[5] == 0) break;  // flushes, as in rtrace
            if (flush_every && (done + block.size() / 6) % flush_every == 0) break;
        }
        if (block.empty()) break;
        if (StopOnSignals::Requested()) throw Interrupted(StopOnSignals::Requested(), "stopped");
        const size_t n = block.size() / 6;
        engines.Trace(
            block, done, columns, [&o](uint64_t) { return o.trace.contrib.irradiance; }, &records);
        if (hits) hits->Find(block.data(), n, &first_hits);
        bytes.clear();
        for (size_t i = 0; i < n; ++i) {
            double value[3] = {0, 0, 0};
            for (int k = 0; k < columns; ++k)
                for (int c = 0; c < 3; ++c) value[c] += records[(i * columns + k) * 3 + c];
            if (o.out == DataFormat::RGBE)
                ValueWriter::Pixel(value, &bytes);
            else
                writer.Put(&block[6 * i], value, hits ? &first_hits[i] : nullptr, &bytes);
        }
        Write(bytes);
        if (std::fflush(stdout) != 0) ErrorExit("write error on standard output");
        done += n;
    }
    if (wanted >= 0 && static_cast<long>(done) < wanted) Warning("unexpected EOF on input");
    engines.Finish();
}

}  // namespace dayflux
