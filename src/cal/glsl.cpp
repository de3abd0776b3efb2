#include "cal/glsl.h"

#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace dayflux::cal {

namespace {

// calcomp's library in GLSL, written once from the series definitions for both precisions: each
// function reduces its argument to a small interval where a Taylor (or atanh) series converges.
// GLSL's own float functions may be thousands of ulps out (Vulkan allows atan 4096 ulps), and it
// has none in double. The template's REAL is float or double, a literal's `@` its suffix ("" or
// LF), and {NAME} what the precisions differ in (MathLibrary): term counts, range limits, and
// ln 2 and pi/2 split in parts so that k times the first part is exact.
constexpr const char *kMathTemplate = R"GLSL(
const REAL cal_PI = 3.14159265358979323846@;
const REAL cal_LN2 = 0.693147180559945309417@;
REAL cal_exp(REAL x) {
    if (x > {EXP_MAX}@) return 1.0@ / 0.0@;  // ln of the largest REAL
    if (x < {EXP_MIN}@) return 0.0@;
    REAL k = floor(x / cal_LN2 + 0.5@);
    REAL r = (x - k * 0.693145751953125@) - k * {LN2_LOW}@;
    REAL term = 1.0@, sum = 1.0@;
    for (int i = 1; i < {EXP_TERMS}; ++i) { term *= r / REAL(i); sum += term; }
    // 2^(largest exponent + 1) is no REAL: the largest results are scaled in two steps.
    return k > {EXP_TOP}@ ? ldexp(sum * 2.0@, int(k) - 1) : ldexp(sum, int(k));
}
REAL cal_log(REAL x) {
    if (x <= 0.0@) return x == 0.0@ ? -1.0@ / 0.0@ : 0.0@ / 0.0@;
    if (isinf(x)) return x;
    int e;
    REAL m = frexp(x, e);
    if (m < 0.70710678118654752440@) { m *= 2.0@; e -= 1; }
    REAL s = (m - 1.0@) / (m + 1.0@), s2 = s * s, term = s, sum = 0.0@;
    for (int i = 0; i < {LOG_TERMS}; ++i) { sum += term / REAL(2 * i + 1); term *= s2; }
    return 2.0@ * sum + REAL(e) * cal_LN2;
}
REAL cal_log10(REAL x) { return cal_log(x) / 2.30258509299404568402@; }
REAL cal_sin_series(REAL r) {
    REAL r2 = r * r, term = r, sum = r;
    for (int i = 1; i < {SIN_TERMS}; ++i) { term *= -r2 / REAL((2 * i) * (2 * i + 1)); sum += term; }
    return sum;
}
REAL cal_cos_series(REAL r) {
    REAL r2 = r * r, term = 1.0@, sum = 1.0@;
    for (int i = 1; i < {SIN_TERMS}; ++i) { term *= -r2 / REAL((2 * i - 1) * (2 * i)); sum += term; }
    return sum;
}
// x = q pi/2 + r with |r| <= pi/4; pi/2 in three parts for the reduction.
REAL cal_reduce(REAL x, out int q) {
    REAL k = floor(x / (cal_PI / 2.0@) + 0.5@);
    q = int(k - 4.0@ * floor(k / 4.0@));
    return ((x - k * {PIO2_1}@) - k * {PIO2_2}@) - k * {PIO2_3}@;
}
REAL cal_sin(REAL x) {
    int q; REAL r = cal_reduce(x, q);
    return q == 0 ? cal_sin_series(r) : q == 1 ? cal_cos_series(r) : q == 2 ? -cal_sin_series(r) : -cal_cos_series(r);
}
REAL cal_cos(REAL x) {
    int q; REAL r = cal_reduce(x, q);
    return q == 0 ? cal_cos_series(r) : q == 1 ? -cal_sin_series(r) : q == 2 ? -cal_cos_series(r) : cal_sin_series(r);
}
REAL cal_tan(REAL x) { return cal_sin(x) / cal_cos(x); }
// atan for |x| <= 1: halve the angle twice (atan x = 2 atan(x / (1 + sqrt(1 + x^2)))), then the series.
REAL cal_atan_unit(REAL x) {
    REAL y = x / (1.0@ + sqrt(1.0@ + x * x));
    y = y / (1.0@ + sqrt(1.0@ + y * y));
    REAL y2 = y * y, term = y, sum = 0.0@;
    for (int i = 0; i < {ATAN_TERMS}; ++i) { sum += term / REAL(2 * i + 1); term *= -y2; }
    return 4.0@ * sum;
}
REAL cal_atan(REAL x) {
    if (abs(x) <= 1.0@) return cal_atan_unit(x);
    return (x > 0.0@ ? cal_PI / 2.0@ : -cal_PI / 2.0@) - cal_atan_unit(1.0@ / x);
}
REAL cal_atan2(REAL y, REAL x) {
    if (x == 0.0@ && y == 0.0@) return 0.0@;
    if (abs(y) <= abs(x)) {
        REAL a = cal_atan_unit(y / x);
        if (x > 0.0@) return a;
        return y >= 0.0@ ? a + cal_PI : a - cal_PI;
    }
    REAL a = cal_atan_unit(x / y);
    return y > 0.0@ ? cal_PI / 2.0@ - a : -cal_PI / 2.0@ - a;
}
// GLSL leaves sqrt of a negative number undefined: outside [-1, 1] these are NaN, as in C.
REAL cal_asin(REAL x) {
    if (!(abs(x) <= 1.0@)) return 0.0@ / 0.0@;
    return cal_atan2(x, sqrt((1.0@ - x) * (1.0@ + x)));
}
REAL cal_acos(REAL x) {
    if (!(abs(x) <= 1.0@)) return 0.0@ / 0.0@;
    return cal_atan2(sqrt((1.0@ - x) * (1.0@ + x)), x);
}
REAL cal_sqrt(REAL x) { return !(x >= 0.0@) ? 0.0@ / 0.0@ : sqrt(x); }
// libfunc()'s and epow()'s rule: a NaN or infinite result is a domain or range error, and 0.
REAL cal_ok(REAL v) { return isnan(v) || isinf(v) ? 0.0@ : v; }
REAL cal_pow(REAL x, REAL y) {
    if (y == 0.0@) return 1.0@;
    if (x == 0.0@) return y > 0.0@ ? 0.0@ : 1.0@ / 0.0@;
    if (x < 0.0@) {
        if (y != floor(y)) return 0.0@ / 0.0@;
        REAL m = cal_exp(y * cal_log(-x));
        return y - 2.0@ * floor(y / 2.0@) == 0.0@ ? m : -m;
    }
    return cal_exp(y * cal_log(x));
}
REAL cal_div(REAL a, REAL b) { return b == 0.0@ ? 0.0@ : a / b; }
REAL cal_rand(REAL x) {
    x *= 1.0@ / (1.0@ + x * x) + 2.71828182845904@;
    x += 0.785398163397447@ - floor(x);
{RAND_FRACTION}
}
)GLSL";

// The library for one precision: kMathTemplate filled in.
std::string MathLibrary(bool single) {
    // rand()'s frac(1e5 / x): in double as calcomp has it; in float from the remainder of 1e5 by
    // x, exact by fma, rather than from the quotient, whose float keeps 7 or 8 bits of fraction.
    const std::map<std::string, std::string> fill = {
        {"{EXP_MAX}", single ? "88.7228390" : "709.782712893384"},
        {"{EXP_MIN}", single ? "-104.0" : "-745.0"},
        {"{LN2_LOW}", single ? "1.428606765330187e-6" : "1.42860682030941723212e-6"},
        {"{EXP_TERMS}", single ? "10" : "20"},
        {"{EXP_TOP}", single ? "127.0" : "1023.0"},
        {"{LOG_TERMS}", single ? "8" : "20"},
        {"{SIN_TERMS}", single ? "7" : "12"},
        {"{PIO2_1}", single ? "1.5703125" : "1.5707963267341256"},
        {"{PIO2_2}", single ? "4.837512969970703125e-4" : "6.077100506506192e-11"},
        {"{PIO2_3}", single ? "7.54978995489188216e-8" : "2.0222662487959506e-21"},
        {"{ATAN_TERMS}", single ? "9" : "18"},
        {"{RAND_FRACTION}", single ? "    REAL q = floor(1e5@ / x);\n"
                                     "    precise REAL r = fma(-q, x, 1e5@);\n"
                                     "    r = r < 0.0@ ? r + x : r >= x ? r - x : r;\n"
                                     "    return r / x;"
                                   : "    x = 1e5@ / x;\n    return x - floor(x);"}};
    std::string s = kMathTemplate;
    for (const auto &[key, value] : fill)
        for (size_t at; (at = s.find(key)) != std::string::npos;) s.replace(at, key.size(), value);
    const std::pair<std::string, std::string> words[] = {{"REAL", single ? "float" : "double"},
                                                         {"@", single ? "" : "LF"}};
    for (const auto &[key, value] : words)
        for (size_t at = 0; (at = s.find(key, at)) != std::string::npos; at += value.size())
            s.replace(at, key.size(), value);
    return s;
}

// A literal of the generated code's type: double (LF, 17 digits) or float (9 digits).
std::string Literal(double v, bool single) {
    const char *suffix = single ? "" : "LF";
    if (v != v) return std::string("(0.0") + suffix + "/0.0" + suffix + ")";
    if (single && std::fabs(v) > 3.4028234663852886e38) v = v > 0 ? 1.0 / 0.0 : -1.0 / 0.0;
    char buf[64];
    auto r =
        std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific, single ? 8 : 17);
    std::string s(buf, r.ptr);
    if (s == "inf") return std::string("(1.0") + suffix + "/0.0" + suffix + ")";
    if (s == "-inf") return std::string("(-1.0") + suffix + "/0.0" + suffix + ")";
    return "(" + s + suffix + ")";
}

class Generator {
  public:
    Generator(const Context &cx, const GlslOptions &o)
        : cx_(cx), o_(o), single_(o.precision == GlslPrecision::kFloat) {}

    std::string Entry(const GlslEntry &e) {
        where_ = e.expr->Text();
        return T() + " " + e.name + "() { return " + Expr(e.expr->Root(), nullptr, 0) + "; }\n";
    }

    std::string Definitions() const {
        std::string s;
        for (const std::string &d : forward_) s += d;
        for (const std::string &d : bodies_) s += d;
        return s;
    }

  private:
    std::string T() const { return single_ ? "float" : "double"; }
    std::string Zero() const { return single_ ? "0.0" : "0.0LF"; }

    [[noreturn]] void Fail(const std::string &msg) const {
        ErrorExit("in '" + where_ + "': " + msg + " (GLSL)");
    }

    // The GLSL name of a definition at an unrolling depth (0 for non-recursive use).
    std::string Emit(int sym, int depth) {
        const Context::Definition *d = cx_.Find(sym);
        const std::string key = std::to_string(sym) + "_" + std::to_string(depth);
        const std::string fname = o_.prefix + key;
        if (emitted_.count(key)) return fname;
        emitted_.insert(key);
        std::string params, decl;
        for (size_t i = 0; i < d->params.size(); ++i)
            params += (i ? ", " : "") + T() + " a" + std::to_string(i + 1);
        forward_.push_back(T() + " " + fname + "(" + params + ");\n");
        std::string body;
        if (depth >= o_.recursion_depth) {
            body = Literal(std::nan(""), single_);  // deeper than unrolled: NaN marks it
        } else {
            active_.push_back(sym);
            body = Expr(d->body.get(), d, depth);
            active_.pop_back();
        }
        bodies_.push_back(T() + " " + fname + "(" + params + ") { return " + body + "; }\n");
        return fname;
    }

    // Depth for a call to sym from the definition currently being generated: a call back into a
    // function on the active chain goes one level deeper.
    int CallDepth(int sym, int depth) const {
        for (int a : active_)
            if (a == sym) return depth + 1;
        return depth;
    }

    std::string Library(const std::string &name, const std::vector<std::string> &a) {
        auto need = [&](size_t n) {
            if (a.size() < n) Fail(name + ": too few arguments");
        };
        if (name == "if") {
            need(3);
            return "((" + a[0] + ") > " + Zero() + " ? (" + a[1] + ") : (" + a[2] + "))";
        }
        if (name == "select") {
            need(1);
            // select(0, ...) gives the number of choices.
            return "((cal_sel_i(" + a[0] + ") == 0) ? " +
                   Literal(static_cast<double>(a.size() - 1), single_) + " : " +
                   Select(a.size() - 1) + "(cal_sel_i(" + a[0] + ")" + Tail(a) + "))";
        }
        if (name == "max" || name == "min") {
            need(1);
            std::string s = a[0];
            for (size_t i = 1; i < a.size(); ++i) s = name + "(" + s + ", " + a[i] + ")";
            return s;
        }
        static const std::map<std::string, std::string> unary = {
            {"sin", "cal_sin"},     {"cos", "cal_cos"},   {"tan", "cal_tan"}, {"asin", "cal_asin"},
            {"acos", "cal_acos"},   {"atan", "cal_atan"}, {"exp", "cal_exp"}, {"log", "cal_log"},
            {"log10", "cal_log10"}, {"sqrt", "cal_sqrt"}, {"floor", "floor"}, {"ceil", "ceil"},
            {"rand", "cal_rand"}};
        auto it = unary.find(name);
        if (it != unary.end()) {
            need(1);
            return "cal_ok(" + it->second + "(" + a[0] + "))";
        }
        if (name == "arg") {
            need(1);
            return "cal_argv(" + a[0] + ")";
        }
        if (name == "atan2") {
            need(2);
            return "cal_ok(cal_atan2(" + a[0] + ", " + a[1] + "))";
        }
        Fail("function '" + name + "' has no GLSL version");
    }

    // select() with n choices: a helper taking the index and every choice (choices are evaluated
    // eagerly here, which is safe because they have no side effects and recursion is unrolled).
    // Its name carries the context's prefix: several contexts share one shader (two receivers
    // of genBSDF with their own -p, each with kbin's selects).
    std::string Select(size_t n) {
        const std::string name = o_.prefix + "_select" + std::to_string(n);
        if (selects_.insert(n).second) {
            std::string params = "int i", body = Literal(std::nan(""), single_);
            for (size_t k = n; k >= 1; --k)
                body =
                    "(i == " + std::to_string(k) + " ? c" + std::to_string(k) + " : " + body + ")";
            for (size_t k = 1; k <= n; ++k) params += ", " + T() + " c" + std::to_string(k);
            std::string helper = T() + " ";
            helper.append(name).append("(").append(params).append(") { return ");
            helper.append(body).append("; }\n");
            forward_.insert(forward_.begin(), helper);
        }
        return name;
    }
    static std::string Tail(const std::vector<std::string> &a) {
        std::string s;
        for (size_t i = 1; i < a.size(); ++i) s += ", " + a[i];
        return s;
    }

    std::string Expr(const Node *n, const Context::Definition *in, int depth) {
        auto kid = [&](int i) { return Expr(n->kids[i].get(), in, depth); };
        switch (n->kind) {
            case Node::kNum:
                return Literal(n->num, single_);
            case Node::kChan:
                if (n->index < 1 || n->index > o_.channels)
                    Fail("channel $" + std::to_string(n->index) + " out of range");
                return "cal_chan[" + std::to_string(n->index) + "]";
            case Node::kArg:
                return "a" + std::to_string(n->index);
            case Node::kAdd:
                return "(" + kid(0) + " + " + kid(1) + ")";
            case Node::kSub:
                return "(" + kid(0) + " - " + kid(1) + ")";
            case Node::kMul:
                return "(" + kid(0) + " * " + kid(1) + ")";
            case Node::kDiv:
                return "cal_div(" + kid(0) + ", " + kid(1) + ")";
            case Node::kPow:
                return "cal_ok(cal_pow(" + kid(0) + ", " + kid(1) + "))";
            case Node::kNeg: {
                std::string s = "(-";  // built in steps: GCC 12 warns falsely on "(-" + string
                s += kid(0);
                s += ")";
                return s;
            }
                return "(-" + kid(0) + ")";
            case Node::kVar: {
                const Context::Definition *d = cx_.Find(n->index);
                if (!d) Fail("undefined variable '" + cx_.SymbolName(n->index) + "'");
                if (!d->params.empty()) Fail("function '" + d->name + "' used as a variable");
                return Emit(n->index, CallDepth(n->index, depth)) + "()";
            }
            case Node::kCall: {
                if (n->kids[0]->kind != Node::kVar)
                    Fail("functions passed as arguments are not supported");
                const int sym = n->kids[0]->index;
                std::vector<std::string> args;
                for (size_t i = 1; i < n->kids.size(); ++i)
                    args.push_back(kid(static_cast<int>(i)));
                const Context::Definition *d = cx_.Find(sym);
                if (!d) return Library(cx_.SymbolName(sym), args);
                if (d->params.empty())
                    Fail("'" + d->name + "' is a variable, called as a function");
                if (args.size() < d->params.size()) Fail(d->name + ": too few arguments");
                std::string call = Emit(sym, CallDepth(sym, depth)) + "(";
                for (size_t i = 0; i < d->params.size(); ++i) call += (i ? ", " : "") + args[i];
                return call + ")";
            }
        }
        return Zero();
    }

    const Context &cx_;
    const GlslOptions &o_;
    const bool single_;
    std::string where_;
    std::set<std::string> emitted_;
    std::set<size_t> selects_;
    std::vector<int> active_;
    std::vector<std::string> forward_, bodies_;
};

}  // namespace

std::string GenerateGlsl(const Context &cx, const std::vector<GlslEntry> &entries,
                         const GlslOptions &options) {
    Generator g(cx, options);
    std::string entry_code;
    for (const GlslEntry &e : entries) entry_code += g.Entry(e);
    std::string s;
    if (options.preamble) {
        const bool single = options.precision == GlslPrecision::kFloat;
        const std::string t = single ? "float" : "double", zero = single ? "0.0" : "0.0LF";
        s += t + " cal_chan[" + std::to_string(options.channels + 1) + "];\n";
        s += MathLibrary(single);
        s += "int cal_sel_i(" + t + " a) { return int(floor(a + 0.5" + (single ? "" : "LF") +
             ")); }\n";
        // A pattern's real arguments: cal_arg[0] is their count, as arg(0).
        s += t + " cal_arg[" + std::to_string(options.max_args + 1) + "];\n";
        s += t + " cal_argv(" + t + " n) { int i = cal_sel_i(n); return i >= 0 && i <= " +
             std::to_string(options.max_args) + " ? cal_arg[i] : " + zero + "; }\n";
    }
    s += g.Definitions();
    s += entry_code;
    return s;
}

}  // namespace dayflux::cal
