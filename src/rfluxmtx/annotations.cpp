#include "rfluxmtx/annotations.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>

#include "scene/reader.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

namespace {

constexpr double kTiny = 1e-6;

// The words of a scene file with their lines; `#@rfluxmtx` lines and `!command` lines are
// handed to callbacks as they come, other comments skipped, as rfluxmtx's load_scene() does.
class Words {
  public:
    Words(std::string text, std::string name) : text_(std::move(text)), name_(std::move(name)) {}

    // The next word (false at the end), after the annotations and commands before it.
    bool Next(std::string *word, const std::function<void(const std::string &, int)> &annotation,
              const std::function<void(const std::string &, int)> &command) {
        for (;;) {
            while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) {
                if (text_[at_] == '\n') ++line_;
                ++at_;
            }
            if (at_ >= text_.size()) return false;
            if (text_[at_] == '!' && at_line_start_ok()) {
                command(RestOfLine(1), line_);
                continue;
            }
            if (text_[at_] == '#') {
                const std::string rest = RestOfLine(1);
                if (rest.rfind("@rfluxmtx", 0) == 0 &&
                    (rest.size() == 9 || std::isspace(static_cast<unsigned char>(rest[9]))))
                    annotation(rest.substr(9), line_);
                continue;
            }
            const size_t start = at_;
            while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_])))
                ++at_;
            *word = text_.substr(start, at_ - start);
            return true;
        }
    }
    bool Next(std::string *word) {
        const auto ignore = [](const std::string &, int) {};
        return Next(word, ignore, ignore);
    }
    FileLoc Loc() const { return FileLoc{name_, line_}; }

  private:
    bool at_line_start_ok() const { return true; }  // load_scene() takes '!' after any blank
    // The rest of the line after `skip` characters (the line counted as read).
    std::string RestOfLine(size_t skip) {
        const size_t start = at_ + skip;
        size_t end = text_.find('\n', start);
        if (end == std::string::npos) end = text_.size();
        at_ = end;
        return text_.substr(start, end - start);
    }

    std::string text_, name_;
    size_t at_ = 0;
    int line_ = 1;
};

// get_direction(): +X, -Y, Z ... or "x,y,z" (normalised); false if it is neither.
bool Direction(const std::string &s, double v[3]) {
    size_t at = 0;
    double sign = 1;
    while (at < s.size() && (s[at] == '+' || s[at] == '-')) sign = s[at++] == '-' ? -sign : sign;
    v[0] = v[1] = v[2] = 0;
    if (at + 1 == s.size()) {
        const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(s[at])));
        if (c >= 'X' && c <= 'Z') {
            v[c - 'X'] = sign;
            return true;
        }
    }
    const std::vector<std::string> parts = Split(s.substr(at), ',');
    if (parts.size() != 3) return false;
    for (int k = 0; k < 3; ++k)
        if (!ParseNumber(parts[k], &v[k]) || !std::isfinite(v[k])) return false;
    v[0] *= sign;
    // Scaled by the largest part first, so that 1e200,1e200,0 does not overflow to inf.
    const double big = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2])});
    if (!(big > 0)) return false;
    for (int k = 0; k < 3; ++k) v[k] /= big;
    const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) v[k] /= l;
    return true;
}

// The largest rN / scN size: r1000 is 144 million bins already.
constexpr int kMaxBasisSize = 1000;

// h=: the basis, as finish_receiver() and prepare_sampler() recognise it.
bool Basis(const std::string &h, FluxBasis *b) {
    std::string s = h;
    b->left_handed = false;
    if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
        b->left_handed = s[0] == '-';
        s = s.substr(1);
    }
    if (s.empty()) return false;
    b->spec = s;
    // The digits give the size (rN, scN); past kMaxBasisSize they stop counting, and the caller
    // refuses the basis (no int overflow, no billions of bins).
    int size = 0;
    for (char c : s)
        if (std::isdigit(static_cast<unsigned char>(c)))
            size = std::min(10 * size + (c - '0'), kMaxBasisSize + 1);
    b->size = size > 0 ? size : 1;
    const char c0 = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
    const char c1 =
        s.size() > 1 ? static_cast<char>(std::tolower(static_cast<unsigned char>(s[1]))) : '\0';
    if (c0 == 'u' || c0 == '1') {
        b->kind = FluxBasis::kUniform;
    } else if (c0 == 's' && c1 == 'c') {
        b->kind = FluxBasis::kShirleyChiu;
    } else if (c0 == 'r' || c0 == 't') {
        b->kind = FluxBasis::kReinhart;
    } else if (c0 == 'k' && (c1 == '\0' || c1 == 'f' || c1 == '1')) {
        b->kind = FluxBasis::kKlemsFull;
    } else if (c0 == 'k' && (c1 == 'h' || c1 == '2')) {
        b->kind = FluxBasis::kKlemsHalf;
    } else if (c0 == 'k' && (c1 == 'q' || c1 == '4')) {
        b->kind = FluxBasis::kKlemsQuarter;
    } else {
        return false;
    }
    return true;
}

// The `#@rfluxmtx` lines since the last surface that took them, with their places.
using Annotations = std::vector<std::pair<std::string, FileLoc>>;

// parse_params(): h=, u= and o= in any order; anything else is an error.
void ApplyAnnotation(const std::string &text, const FileLoc &loc, FluxGroup *g) {
    const std::vector<std::string> words = SplitWords(text);
    for (size_t i = 0; i < words.size(); ++i) {
        const std::string &w = words[i];
        const size_t eq = w.find('=');
        const std::string key = eq == std::string::npos ? w : w.substr(0, eq);
        const std::string value = eq == std::string::npos ? "" : w.substr(eq + 1);
        if (key == "h" && !value.empty()) {
            if (!Basis(value, &g->basis))
                ErrorExit(&loc, "unrecognized hemisphere sampling: h=" + value);
            if (g->basis.size > kMaxBasisSize)
                ErrorExit(&loc, "h=" + value + ": a basis size above " +
                                    std::to_string(kMaxBasisSize) +
                                    " (more bins than a matrix of ours can hold)");
            g->has_basis = true;
        } else if (key == "u") {
            if (!Direction(value, g->up))
                ErrorExit(&loc, "bad parameter string: '" + w +
                                    "' (an up vector is +X, -Y, ... or three finite numbers, "
                                    "not all 0)");
        } else if (key == "o" && !value.empty()) {
            std::string out = value;
            if (out[0] == '"' || out[0] == '\'') {  // a quoted name may hold blanks
                const char quote = out[0];
                out = out.substr(1);
                while (out.find(quote) == std::string::npos && i + 1 < words.size())
                    out += " " + words[++i];
                if (out.find(quote) == std::string::npos)
                    ErrorExit(&loc, "bad parameter string: unterminated o=" + value);
                out = out.substr(0, out.find(quote));
            }
            g->output = out;
        } else {
            ErrorExit(&loc, "bad parameter string: '" + w + "' (h=, u= or o=)");
        }
    }
}

void ApplyAnnotations(const Annotations &params, FluxGroup *g) {
    for (const auto &[text, loc] : params) ApplyAnnotation(text, loc, g);
}

// add_surface(): a polygon, ring or source with its normal and area; false (with RADIANCE's
// warning) for one of no area.
bool MakeSurface(FluxSurface *s) {
    const std::vector<double> &a = s->args;
    const auto bad_count = [&] {
        ErrorExit(&s->loc, "bad argument count for surface element '" + s->name + "'");
    };
    const auto unit = [&](double x, double y, double z) {
        const double l = std::sqrt(x * x + y * y + z * z);
        if (l == 0) ErrorExit(&s->loc, "bad orientation for surface element '" + s->name + "'");
        s->normal[0] = x / l, s->normal[1] = y / l, s->normal[2] = z / l;
    };
    switch (s->type) {
        case FluxSurface::kRing: {
            if (a.size() != 8) bad_count();
            unit(a[3], a[4], a[5]);
            const double r0 = std::min(a[6], a[7]), r1 = std::max(a[6], a[7]);
            s->args[6] = r0, s->args[7] = r1;
            s->area = M_PI * (r1 * r1 - r0 * r0);
            break;
        }
        case FluxSurface::kPolygon: {
            if (a.size() < 9 || a.size() % 3) bad_count();
            // finish_polygon(): the fan's cross products, summed.
            double n[3] = {0, 0, 0}, e1[3], e2[3];
            for (int k = 0; k < 3; ++k) e1[k] = a[3 + k] - a[k];
            for (size_t i = 2; i < a.size() / 3; ++i) {
                for (int k = 0; k < 3; ++k) e2[k] = a[3 * i + k] - a[k];
                n[0] += e1[1] * e2[2] - e1[2] * e2[1];
                n[1] += e1[2] * e2[0] - e1[0] * e2[2];
                n[2] += e1[0] * e2[1] - e1[1] * e2[0];
                for (int k = 0; k < 3; ++k) e1[k] = e2[k];
            }
            const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int k = 0; k < 3; ++k) s->normal[k] = l > 0 ? n[k] / l : 0;
            s->area = .5 * l;
            break;
        }
        case FluxSurface::kSource: {
            if (a.size() != 4) bad_count();
            unit(-a[0], -a[1], -a[2]);
            const double sh = std::sin(M_PI / 180. / 2. * a[3]);
            s->area = M_PI * sh * sh;
            break;
        }
    }
    if (s->area <= kTiny * kTiny) {
        Warning(&s->loc, "zero area for surface '" + s->name + "'");
        return false;
    }
    return true;
}

// The arguments of an object: strings, integers (skipped) and reals.
std::vector<double> RealArguments(Words &words, const FileLoc &loc, const std::string &name) {
    std::string w;
    // A count is a whole number, and the arguments it counts must follow: they are read one by
    // one, never allocated ahead from the count.
    const auto count = [&] {
        int n;
        if (!words.Next(&w) || !ParseInt(w, &n) || n < 0)
            ErrorExit(&loc, "bad argument count for '" + name + "'");
        return n;
    };
    for (int part = 0; part < 2; ++part)
        for (int i = count(); i > 0; --i)
            if (!words.Next(&w)) ErrorExit(&loc, "unexpected end of file in '" + name + "'");
    std::vector<double> reals;
    for (int i = count(); i > 0; --i) {
        double x;
        if (!words.Next(&w) || !ParseNumber(w, &x))
            ErrorExit(&loc, "error reading arguments for '" + name + "'");
        if (!std::isfinite(x))
            ErrorExit(&loc, "argument '" + w + "' of '" + name + "' is not a number");
        reals.push_back(x);
    }
    return reals;
}

bool SurfaceType(const std::string &type, FluxSurface::Type *t) {
    if (type == "polygon")
        *t = FluxSurface::kPolygon;
    else if (type == "ring")
        *t = FluxSurface::kRing;
    else if (type == "source")
        *t = FluxSurface::kSource;
    else
        return false;
    return true;
}

// The surface as xform puts it out: moved, turned, scaled or mirrored (a mirrored polygon's
// vertices reversed and a ring's normal negated, so that its front stays its front).
void TransformSurface(const Transform &xf, FluxSurface *s) {
    std::vector<double> &a = s->args;
    const bool mirrors = xf.Mirrors();
    switch (s->type) {
        case FluxSurface::kPolygon:
            if (a.size() % 3) return;  // MakeSurface() reports it
            for (size_t k = 0; k < a.size(); k += 3) {
                const double p[3] = {a[k], a[k + 1], a[k + 2]};
                xf.Apply(p, &a[k]);
            }
            if (mirrors)
                for (size_t i = 0, j = a.size() / 3 - 1; i < j; ++i, --j)
                    std::swap_ranges(&a[3 * i], &a[3 * i + 3], &a[3 * j]);
            break;
        case FluxSurface::kRing: {
            if (a.size() != 8) return;
            const double c[3] = {a[0], a[1], a[2]}, n[3] = {a[3], a[4], a[5]};
            xf.Apply(c, &a[0]);
            xf.ApplyDirection(n, &a[3]);
            if (mirrors)
                for (int k = 3; k < 6; ++k) a[k] = -a[k];
            a[6] *= xf.scale, a[7] *= xf.scale;
            break;
        }
        case FluxSurface::kSource: {
            if (a.size() != 4) return;
            const double d[3] = {a[0], a[1], a[2]};
            xf.ApplyDirection(d, &a[0]);
            break;
        }
    }
}

// Reads one file (or command's output) of a sender or receiver, calling `surface` for each
// polygon, ring and source with its modifier, after the annotations before it (other objects
// are skipped). "!xform" lines are done in-process, as SceneReader does them; other commands
// go to the shell.
class FluxReader {
  public:
    using Surface = std::function<void(const std::string &mod, FluxSurface &s)>;
    FluxReader(Surface surface, Annotations *params)
        : surface_(std::move(surface)), params_(*params) {}

    void Read(const std::string &spec, int depth) { Read(spec, depth, XformCommand{}); }

  private:
    // `outer`: the xform commands around this file, composed (its files unused).
    void Read(const std::string &spec, int depth, const XformCommand &outer) {
        if (depth > 32) ErrorExit("'" + spec + "': !commands nested too deep");
        const std::unique_ptr<InputSource> in = InputSource::Open(spec);
        std::string text = in->ReadAll();
        if (!in->Close()) ErrorExit("error loading '" + spec + "'");
        Words words(std::move(text), in->Name());
        std::string mod, type, obj;
        const auto annotation = [&](const std::string &a, int line) {
            params_.push_back({a, FileLoc{in->Name(), line}});
        };
        const auto command = [&](const std::string &c, int line) {
            XformCommand xform;
            const FileLoc loc{in->Name(), line};
            if (!ParseXformCommand(c, loc, &xform)) {
                if (!CommandsInDataFilesAllowed()) InputSource::OpenNamedIn("!" + c, loc);
                return Read("!" + c, depth + 1, outer);
            }
            xform.xf = xform.xf.Then(outer.xf);
            if (!outer.modifier.empty()) xform.modifier = outer.modifier;  // the outer -m wins
            xform.name_prefix = outer.name_prefix + xform.name_prefix;
            for (const std::string &f : xform.files) Read(f, depth + 1, xform);
        };
        while (words.Next(&mod, annotation, command)) {
            const FileLoc loc = words.Loc();
            if (!words.Next(&type) || !words.Next(&obj))
                ErrorExit(&loc, "unexpected end of file in object of '" + mod + "'");
            if (type == "alias") {
                std::string skipped;
                if (!words.Next(&skipped)) ErrorExit(&loc, "unexpected end of file in alias");
                continue;
            }
            FluxSurface s;
            s.args = RealArguments(words, loc, obj);
            if (!SurfaceType(type, &s.type)) continue;
            if (!outer.xf.identity) TransformSurface(outer.xf, &s);
            s.name = outer.name_prefix + obj;
            s.loc = loc;
            surface_(outer.modifier.empty() ? mod : outer.modifier, s);
        }
    }

    Surface surface_;
    Annotations &params_;
};

}  // namespace

void FluxGroup::Normal(double n[3]) const {
    n[0] = n[1] = n[2] = 0;
    for (const FluxSurface &s : surfaces)
        for (int k = 0; k < 3; ++k) n[k] += s.area * s.normal[k];
    const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l == 0) ErrorExit(&loc, "undefined normal for hemisphere sampling ('" + modifier + "')");
    for (int k = 0; k < 3; ++k) n[k] /= l;
}

void FluxGroup::Up(double u[3]) const {
    double n[3];
    Normal(n);
    for (int k = 0; k < 3; ++k) u[k] = up[k];
    if (u[0] == 0 && u[1] == 0 && u[2] == 0) {
        u[std::fabs(n[2]) < .7 ? 2 : 1] = 1;
        return;
    }
    // An up vector along the normal leaves the hemisphere's azimuths undefined.
    const double c[3] = {u[1] * n[2] - u[2] * n[1], u[2] * n[0] - u[0] * n[2],
                         u[0] * n[1] - u[1] * n[0]};
    if (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] < kTiny * kTiny)
        ErrorExit(&loc, "up vector (u=) coincides with the normal of '" + modifier + "'");
}

std::vector<FluxGroup> ReadReceivers(const std::string &path) {
    std::vector<FluxGroup> groups;
    Annotations params;
    bool sources = false;
    FluxReader reader(
        [&](const std::string &mod, FluxSurface &s) {
            if (!groups.empty() && (s.type == FluxSurface::kSource) != sources)
                ErrorExit(&s.loc, "cannot mix source and non-source receivers ('" + s.name + "')");
            sources = s.type == FluxSurface::kSource;
            if (groups.empty() || mod != groups.back().modifier) {
                // h= carries over from one receiver to the next, as in rfluxmtx.
                FluxGroup g;
                g.has_basis = groups.empty() ? false : groups.back().has_basis;
                if (!groups.empty()) g.basis = groups.back().basis;
                g.modifier = mod;
                g.loc = s.loc;
                ApplyAnnotations(params, &g);
                params.clear();
                groups.push_back(g);
            }
            if (MakeSurface(&s)) groups.back().surfaces.push_back(s);
        },
        &params);
    reader.Read(path, 0);
    if (groups.empty()) ErrorExit(path + ": missing receiver surface");
    for (const FluxGroup &g : groups) {
        if (!g.has_basis)
            ErrorExit(&g.loc, "missing hemisphere sampling type (h=) for '" + g.modifier + "'");
        if (g.surfaces.empty())
            ErrorExit(&g.loc, "receiver '" + g.modifier + "' has no surface of any area");
        if (g.basis.kind != FluxBasis::kUniform && g.surfaces[0].type == FluxSurface::kSource)
            for (const FluxSurface &s : g.surfaces)
                if (std::fabs(s.area - M_PI) > 1e-3)
                    ErrorExit(&s.loc, "source '" + s.name + "' must be 180-degrees");
    }
    return groups;
}

FluxGroup ReadSender(const std::string &path) {
    FluxGroup g;
    Annotations params;
    bool warned = false;
    FluxReader reader(
        [&](const std::string &mod, FluxSurface &s) {
            if (s.type == FluxSurface::kSource)
                ErrorExit(&s.loc, "cannot use source '" + s.name + "' as a sender");
            if (g.modifier.empty()) {
                g.modifier = mod;
                g.loc = s.loc;
            } else if (mod != g.modifier && !warned) {
                Warning(&s.loc, "multiple modifiers in sender");
                warned = true;
            }
            ApplyAnnotations(params, &g);
            params.clear();
            if (MakeSurface(&s)) g.surfaces.push_back(s);
        },
        &params);
    reader.Read(path, 0);
    if (g.surfaces.empty()) ErrorExit(path + ": no sender surface");
    if (!g.has_basis) ErrorExit(&g.loc, "missing sender sampling type (h=)");
    if (!g.output.empty()) Warning("ignoring output file in sender ('" + g.output + "')");
    return g;
}

}  // namespace dayflux
