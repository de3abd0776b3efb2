#include "cal/calcomp.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "cal/calcomp_impl.h"
#include "cal/direct_bins.h"
#include "cal/specialise.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux::cal {

namespace {

struct LibraryEntry {
    const char *name;
    Library fn;
    int nargs;  // -1: any number
};

constexpr LibraryEntry kLibrary[] = {
    {"acos", Library::kAcos, 1},   {"asin", Library::kAsin, 1},   {"atan", Library::kAtan, 1},
    {"atan2", Library::kAtan2, 2}, {"ceil", Library::kCeil, 1},   {"cos", Library::kCos, 1},
    {"exp", Library::kExp, 1},     {"floor", Library::kFloor, 1}, {"if", Library::kIf, 3},
    {"log", Library::kLog, 1},     {"log10", Library::kLog10, 1}, {"max", Library::kMax, -1},
    {"min", Library::kMin, -1},    {"rand", Library::kRand, 1},   {"select", Library::kSelect, -1},
    {"sin", Library::kSin, 1},     {"sqrt", Library::kSqrt, 1},   {"tan", Library::kTan, 1},
    {"erf", Library::kErf, 1},     {"erfc", Library::kErfc, 1},   {"arg", Library::kArg, 1},
};

constexpr int kMaxDepth = 2000;  // calls deeper than this are taken as recursion without end
// Expressions deeper than this are refused where they are read: evaluating, specialising and
// freeing them recurses, and no real .cal file comes near (a chain a+b+c... is as deep as long).
constexpr int kMaxHeight = 1000;
constexpr int kMaxChannel = 100000;  // $N
// The stack one evaluation may use: a definition that reaches itself through arg() or a chain
// of deep expressions runs out of stack long before kMaxDepth calls (sooner in TBB's threads and
// in sanitizer builds); real .cal files use a few kilobytes.
constexpr std::ptrdiff_t kMaxStackBytes = 1 << 20;

bool IsIdChar(int c) { return std::isalnum(c) || c == '_' || c == '.' || c == '`'; }

}  // namespace

void WarnOfDomainError(Library fn, bool range) {
    static std::atomic<uint64_t> warned{0};
    const uint64_t bit = uint64_t{1} << (2 * static_cast<int>(fn) + (range ? 1 : 0));
    if (warned.fetch_or(bit) & bit) return;
    std::string name = "power";
    for (const LibraryEntry &e : kLibrary)
        if (e.fn == fn) name = e.name;
    Warning(name + (range ? ": range error" : ": domain error") + " (0 used, as RADIANCE does)");
}

// Evaluation with activation frames: arguments are expressions of the caller, evaluated on first
// use and remembered, as RADIANCE does (so if() evaluates only the branch it takes).
struct Evaluator {
    // Each evaluator is one top-level evaluation: variables cached by earlier ones (another
    // ray, or definitions since changed) are computed afresh.
    Evaluator(const Context::Impl &c, const Channels *ch, const FileLoc *w)
        : cx(c), channels(ch), where(w) {
        ++cx.epoch;
    }
    const Context::Impl &cx;
    const Channels *channels;
    const FileLoc *where;
    int depth = 0;
    bool read_ray = false;  // the evaluation so far read a ray variable or an object argument

    // Fails when this evaluation's stack (from the evaluator, which lives on the caller's
    // stack, to here) passes kMaxStackBytes.
    void CheckStack(const std::string &what) const {
        const char here = 0;
        const std::ptrdiff_t used = reinterpret_cast<const char *>(this) - &here;
        if (used > kMaxStackBytes || used < -kMaxStackBytes) Fail("recursion without end " + what);
    }

    struct Frame {
        Frame(const Frame *c, const Node *const *a, int n, const std::string *nm)
            : caller(c), args(a), nargs(n), name(nm) {}
        const Frame *caller;
        const Node *const *args;  // argument expressions (in the caller's frame)
        int nargs;
        const std::string *name;
        mutable double value[16];  // read only where `have` says it was set
        mutable unsigned have = 0;
    };

    [[noreturn]] void Fail(const std::string &msg) const { ErrorExit(where, msg); }

    double Arg(const Frame *f, int i) {
        if (!f || i < 1 || i > f->nargs)
            Fail(std::string(f && f->name ? *f->name : "expression") + ": too few arguments");
        if (i <= 16 && (f->have >> (i - 1) & 1u)) return f->value[i - 1];
        const double v = Eval(f->args[i - 1], f->caller);
        if (i <= 16) f->value[i - 1] = v, f->have |= 1u << (i - 1);
        return v;
    }

    double Variable(int sym) {
        const Context::Definition *d = cx.defs[sym].get();
        if (!d) {
            if (cx.library[sym] != Library::kNone)
                Fail("'" + cx.names[sym] + "' is a function, used as a variable");
            Fail("undefined variable '" + cx.names[sym] + "'");
        }
        if (!d->params.empty()) Fail("function '" + cx.names[sym] + "' used as a variable");
        if (d->constant && cx.have_constant[sym]) return cx.constant_value[sym];
        if (!d->constant && cx.variable_epoch[sym] == cx.epoch) return cx.variable_value[sym];
        if (++depth > kMaxDepth) Fail("recursion without end evaluating '" + cx.names[sym] + "'");
        CheckStack("evaluating '" + cx.names[sym] + "'");
        const FileLoc *outer = where;
        where = &d->loc;
        const bool outer_read_ray = read_ray;
        read_ray = false;
        const double v = Eval(d->body.get(), nullptr);
        const bool body_read_ray = read_ray;
        read_ray = outer_read_ray || body_read_ray;
        where = outer;
        --depth;
        // A constant (':') that reads the ray is not one: evaluated again each time, as the
        // specialised evaluation does (RADIANCE keeps its first value: docs/compat.md).
        if (!d->constant)
            cx.variable_epoch[sym] = cx.epoch, cx.variable_value[sym] = v;
        else if (!body_read_ray)
            cx.have_constant[sym] = 1, cx.constant_value[sym] = v;
        return v;
    }

    double LibraryCall(Library fn, const std::string &name, const Frame *f) {
        auto a = [&](int i) { return Arg(f, i); };
        switch (fn) {
            case Library::kIf:
                return a(1) > 0.0 ? a(2) : a(3);
            case Library::kSelect: {
                const double a1 = a(1);
                // Checked as a double first: NaN or a huge index must not reach the cast.
                if (!(a1 >= -.5 && a1 + .5 < f->nargs))
                    Fail("select: index " + FormatNumber(a1) + " out of range");
                const int n = static_cast<int>(a1 + .5);
                if (n == 0) return f->nargs - 1;
                return a(n + 1);
            }
            case Library::kMax:
            case Library::kMin: {
                double v = a(1);
                for (int i = f->nargs; i > 1; --i) {
                    const double x = a(i);
                    if (fn == Library::kMax ? v < x : v > x) v = x;
                }
                return v;
            }
            case Library::kAtan2:
                return LibraryMath(fn, a(1), a(2));
            case Library::kRand:
            case Library::kAcos:
            case Library::kAsin:
            case Library::kAtan:
            case Library::kCeil:
            case Library::kCos:
            case Library::kExp:
            case Library::kFloor:
            case Library::kLog:
            case Library::kLog10:
            case Library::kSin:
            case Library::kSqrt:
            case Library::kTan:
            case Library::kErf:
            case Library::kErfc:
                return LibraryMath(fn, a(1));
            case Library::kArg: {
                const std::vector<double> *args = channels ? channels->ObjectArguments() : nullptr;
                if (!args) Fail("arg() used where there is no object");
                read_ray = true;
                const double a1 = a(1);
                if (!(a1 >= -.5 && a1 + .5 < static_cast<double>(args->size()) + 1))
                    Fail("arg(" + FormatNumber(a1) + "): the object has " +
                         std::to_string(args->size()) + " arguments");
                const int n = static_cast<int>(a1 + .5);
                if (n == 0) return static_cast<double>(args->size());
                return (*args)[n - 1];
            }
            case Library::kIn: {
                read_ray = true;
                const double a1 = a(1);
                // RADIANCE's (int)(argument(1) + .5); a NaN or what no int holds is checked first
                if (!(a1 > -2147483648.0 && a1 < 2147483647.0)) Fail("illegal channel number");
                const int n = static_cast<int>(a1 + .5);
                if (!channels) Fail("in() used where there are no columns");
                return n != 0 ? channels->Value(n) : channels->Count();
            }
            case Library::kNone:
                break;
        }
        Fail("undefined function '" + name + "'");
    }

    double Call(const Node *n, const Frame *f) {
        // The callee is a symbol, or an argument that names a function (functions as arguments).
        int sym = n->kids[0]->index;
        if (n->kids[0]->kind == Node::kArg) {
            const Node *actual = f && sym <= f->nargs ? f->args[sym - 1] : nullptr;
            if (!actual || actual->kind != Node::kVar) Fail("argument is not a function");
            sym = actual->index;
            // The named function's arguments still come from this call's expressions.
        }
        const int nargs = static_cast<int>(n->kids.size()) - 1;
        // Argument lists are short: keep them on the stack (this is the hot path of bin
        // functions such as kbin).
        const Node *small[8];
        std::vector<const Node *> large;
        const Node **args = small;
        if (nargs > 8) large.resize(nargs), args = large.data();
        for (int i = 0; i < nargs; ++i) args[i] = n->kids[i + 1].get();
        Frame frame(f, args, nargs, &cx.names[sym]);
        const Context::Definition *d = cx.defs[sym].get();
        if (!d || d->params.empty()) {
            if (d) Fail("'" + cx.names[sym] + "' is a variable, called as a function");
            return LibraryCall(cx.library[sym], cx.names[sym], &frame);
        }
        if (nargs < static_cast<int>(d->params.size())) Fail(cx.names[sym] + ": too few arguments");
        if (++depth > kMaxDepth) Fail("recursion without end in '" + cx.names[sym] + "'");
        CheckStack("in '" + cx.names[sym] + "'");
        const FileLoc *outer = where;
        where = &d->loc;
        const double v = Eval(d->body.get(), &frame);
        where = outer;
        --depth;
        return v;
    }

    double Eval(const Node *n, const Frame *f) {
        switch (n->kind) {
            case Node::kNum:
                return n->num;
            case Node::kVar:
                return Variable(n->index);
            case Node::kArg:
                return Arg(f, n->index);
            case Node::kChan:
                if (!channels)
                    Fail("ray variable $" + std::to_string(n->index) +
                         " used where there is no ray");
                read_ray = true;
                return channels->Value(n->index);
            case Node::kCall:
                return Call(n, f);
            case Node::kAdd:
                return Eval(n->kids[0].get(), f) + Eval(n->kids[1].get(), f);
            case Node::kSub:
                return Eval(n->kids[0].get(), f) - Eval(n->kids[1].get(), f);
            case Node::kMul:
                return Eval(n->kids[0].get(), f) * Eval(n->kids[1].get(), f);
            case Node::kDiv: {
                const double d = Eval(n->kids[1].get(), f);
                if (d == 0) return 0;  // RADIANCE warns "Division by zero" and gives 0
                return Eval(n->kids[0].get(), f) / d;
            }
            case Node::kPow:
                return Power(Eval(n->kids[0].get(), f), Eval(n->kids[1].get(), f));
            case Node::kNeg:
                return -Eval(n->kids[0].get(), f);
        }
        return 0;
    }
};

namespace {

// Recursive-descent parser with RADIANCE's grammar and its constant reductions.
class Parser {
  public:
    Parser(Context::Impl &cx, std::string_view text, const FileLoc &loc)
        : cx_(cx), s_(text), loc_(loc) {
        line_ = loc.line > 0 ? loc.line : 1;
        Skip();
    }

    bool AtEnd() const { return pos_ >= s_.size(); }

    void Statement() {
        if (Peek() == ';') {
            Next();
            return;
        }
        auto def = std::make_unique<Context::Definition>();
        if (Peek() == '$' && cx_.output_channels) {
            // rcalc's "$N = e;": output channel N, kept under the name "$N", which no
            // expression can name.
            Next();
            int n = 0;
            while (std::isdigit(Peek()) && n <= kMaxChannel) n = n * 10 + (Next() - '0');
            if (n < 1 || n > kMaxChannel)
                Syntax("output channel beyond $1..$" + std::to_string(kMaxChannel));
            def->name = "$" + std::to_string(n);
            def->loc = Here();
            if (Peek() != '=') Syntax("'=' expected");
        } else {
            if (!(std::isalpha(Peek()) || Peek() == '`')) Syntax("illegal variable name");
            def->name = Name();
            def->loc = Here();
        }
        if (Peek() == '(') {
            do {
                Next();
                if (!std::isalpha(Peek())) Syntax("illegal parameter name");
                def->params.push_back(Name());
            } while (Peek() == ',');
            if (Peek() != ')') Syntax("')' expected");
            Next();
        }
        if (Peek() != '=' && Peek() != ':') Syntax("'=' or ':' expected");
        def->constant = Next() == ':';
        params_ = &def->params;
        def->body = E1();
        params_ = nullptr;
        if (!AtEnd()) {
            if (Peek() != ';') Syntax("';' expected");
            Next();
        }
        const int sym = cx_.Intern(def->name);
        def->name = cx_.names[sym];
        cx_.defs[sym] = std::move(def);
        cx_.Invalidate();
    }

    NodePtr Expression() {
        NodePtr e = E1();
        if (!AtEnd()) Syntax("unexpected character");
        return e;
    }

    FileLoc Here() const { return FileLoc{loc_.file, line_}; }

  private:
    int Peek() const { return pos_ < s_.size() ? static_cast<unsigned char>(s_[pos_]) : -1; }
    int Next() {
        const int c = Peek();
        ++pos_;
        Skip();
        return c;
    }
    // Skips white space and {comments} (which nest, as in RADIANCE).
    void Skip() {
        for (;;) {
            while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])))
                line_ += s_[pos_++] == '\n';
            if (pos_ < s_.size() && s_[pos_] == '{') {
                int level = 0;
                do {
                    if (pos_ >= s_.size()) Syntax("'}' expected");
                    if (s_[pos_] == '{') ++level;
                    if (s_[pos_] == '}') --level;
                    line_ += s_[pos_] == '\n';
                    ++pos_;
                } while (level > 0);
                continue;
            }
            return;
        }
    }
    // Names may be split by comments or spaces in RADIANCE; we read them as contiguous words.
    std::string Name() {
        std::string n;
        while (pos_ < s_.size() && IsIdChar(static_cast<unsigned char>(s_[pos_]))) n += s_[pos_++];
        Skip();
        return n;
    }
    double Number() {
        size_t start = pos_;
        while (std::isdigit(Peek())) ++pos_;
        if (Peek() == '.') {
            ++pos_;
            if (pos_ - start == 1 && !std::isdigit(Peek())) Syntax("badly formed number");
            while (std::isdigit(Peek())) ++pos_;
        }
        if (Peek() == 'e' || Peek() == 'E') {
            ++pos_;
            if (Peek() == '-' || Peek() == '+') ++pos_;
            if (!std::isdigit(Peek())) Syntax("missing exponent");
            while (std::isdigit(Peek())) ++pos_;
        }
        const double v = std::strtod(std::string(s_.substr(start, pos_ - start)).c_str(), nullptr);
        Skip();
        return v;
    }
    [[noreturn]] void Syntax(const std::string &msg) const {
        FileLoc here = Here();
        std::string near = pos_ < s_.size() ? std::string(s_.substr(pos_, 20)) : "end of input";
        ErrorExit(&here, msg + " at '" + near.substr(0, near.find('\n')) + "'");
    }

    static NodePtr Num(double v) {
        auto n = std::make_unique<Node>();
        n->kind = Node::kNum;
        n->num = v;
        return n;
    }
    NodePtr Op(Node::Kind k, NodePtr a, NodePtr b = nullptr) const {
        auto n = std::make_unique<Node>();
        n->kind = k;
        n->kids.push_back(std::move(a));
        if (b) n->kids.push_back(std::move(b));
        return Grown(std::move(n));
    }
    // n with its height from its kids', refused beyond kMaxHeight.
    NodePtr Grown(NodePtr n) const {
        for (const NodePtr &kid : n->kids) n->height = std::max(n->height, kid->height + 1);
        if (n->height > kMaxHeight)
            Syntax("expression nested deeper than " + std::to_string(kMaxHeight) + " levels");
        return n;
    }
    // Counts the parser's own recursion (parentheses, unary signs, ^ chains) against the same
    // limit, so that the stack is safe before any tree is built.
    class Nested {
      public:
        explicit Nested(Parser *p) : p_(p) {
            if (++p_->nesting_ > kMaxHeight)
                p_->Syntax("expression nested deeper than " + std::to_string(kMaxHeight) +
                           " levels");
        }
        ~Nested() { --p_->nesting_; }
        Nested(const Nested &) = delete;
        Nested &operator=(const Nested &) = delete;

      private:
        Parser *p_;
    };
    // Reduces a node whose operands are all numbers, as RADIANCE's rconst().
    NodePtr Reduce(NodePtr n) {
        Evaluator ev(cx_, nullptr, nullptr);
        FileLoc here = Here();
        ev.where = &here;
        return Num(ev.Eval(n.get(), nullptr));
    }

    NodePtr E1() {
        const Nested nested(this);
        NodePtr a = E2();
        while (Peek() == '+' || Peek() == '-') {
            const Node::Kind k = Next() == '+' ? Node::kAdd : Node::kSub;
            NodePtr b = E2();
            const bool fold = a->kind == Node::kNum && b->kind == Node::kNum;
            a = Op(k, std::move(a), std::move(b));
            if (fold) a = Reduce(std::move(a));
        }
        return a;
    }
    NodePtr E2() {
        NodePtr a = E3();
        while (Peek() == '*' || Peek() == '/') {
            Node::Kind k = Next() == '*' ? Node::kMul : Node::kDiv;
            NodePtr b = E3();
            if (a->kind == Node::kNum && b->kind == Node::kNum) {
                a = Reduce(Op(k, std::move(a), std::move(b)));
            } else if (b->kind == Node::kNum) {
                if (k == Node::kDiv) {  // RADIANCE multiplies by the reciprocal of a constant
                    if (b->num == 0) Syntax("divide by zero constant");
                    k = Node::kMul;
                    b->num = 1. / b->num;
                    a = Op(k, std::move(a), std::move(b));
                } else if (b->num == 0) {
                    a = std::move(b);
                } else {
                    a = Op(k, std::move(a), std::move(b));
                }
            } else if (a->kind == Node::kNum && a->num == 0) {
                // 0 * E and 0 / E are 0
            } else {
                a = Op(k, std::move(a), std::move(b));
            }
        }
        return a;
    }
    NodePtr E3() {
        NodePtr a = E4();
        if (Peek() != '^') return a;
        const Nested nested(this);
        Next();
        NodePtr b = E3();
        if (a->kind == Node::kNum && b->kind == Node::kNum)
            return Reduce(Op(Node::kPow, std::move(a), std::move(b)));
        if (a->kind == Node::kNum && a->num == 0) return a;
        if ((b->kind == Node::kNum && b->num == 0) || (a->kind == Node::kNum && a->num == 1))
            return Num(1);
        if (b->kind == Node::kNum && b->num == 1) return a;
        return Op(Node::kPow, std::move(a), std::move(b));
    }
    NodePtr E4() {
        if (Peek() == '-') {
            const Nested nested(this);
            Next();
            NodePtr a = E5();
            if (a->kind == Node::kNum) {
                a->num = -a->num;
                return a;
            }
            if (a->kind == Node::kNeg) return std::move(a->kids[0]);
            return Op(Node::kNeg, std::move(a));
        }
        if (Peek() == '+') Next();
        return E5();
    }
    NodePtr E5() {
        if (Peek() == '(') {
            Next();
            NodePtr a = E1();
            if (Peek() != ')') Syntax("')' expected");
            Next();
            return a;
        }
        if (Peek() == '$') {
            Next();
            int n = 0;
            while (std::isdigit(Peek())) {
                n = n * 10 + (Next() - '0');
                if (n > kMaxChannel)
                    Syntax("channel number beyond $" + std::to_string(kMaxChannel));
            }
            auto c = std::make_unique<Node>();
            c->kind = Node::kChan;
            c->index = n;
            return c;
        }
        if (std::isalpha(Peek()) || Peek() == '`') {
            std::string name = Name();
            NodePtr ref = std::make_unique<Node>();
            ref->kind = Node::kVar;
            if (params_) {
                for (size_t i = 0; i < params_->size(); ++i)
                    if ((*params_)[i] == name)
                        ref->kind = Node::kArg, ref->index = static_cast<int>(i) + 1;
            }
            if (ref->kind == Node::kVar) ref->index = cx_.Intern(name);
            if (Peek() == '(') {
                auto call = std::make_unique<Node>();
                call->kind = Node::kCall;
                call->kids.push_back(std::move(ref));
                do {
                    Next();
                    call->kids.push_back(E1());
                } while (Peek() == ',');
                if (Peek() != ')') Syntax("')' expected");
                Next();
                return FoldConstantCall(Grown(std::move(call)));
            }
            return FoldConstantVariable(std::move(ref));
        }
        if (std::isdigit(Peek()) || Peek() == '.') return Num(Number());
        Syntax("unexpected character");
    }

    // A reference to a ':' variable already defined by a constant expression becomes its value.
    NodePtr FoldConstantVariable(NodePtr ref) {
        if (ref->kind != Node::kVar) return ref;
        const Context::Definition *d = cx_.defs[ref->index].get();
        if (!d || !d->constant || !d->params.empty()) return ref;
        try {
            Evaluator ev(cx_, nullptr, &d->loc);
            return Num(ev.Eval(d->body.get(), nullptr));
        } catch (const UserError &) {
            return ref;  // depends on something not yet defined, or on a ray: evaluate later
        }
    }
    // A call of a ':' function or library function with constant arguments is reduced too.
    NodePtr FoldConstantCall(NodePtr call) {
        const Node *callee = call->kids[0].get();
        if (callee->kind != Node::kVar) return call;
        for (size_t i = 1; i < call->kids.size(); ++i)
            if (call->kids[i]->kind != Node::kNum) return call;
        const Context::Definition *d = cx_.defs[callee->index].get();
        const bool constant =
            d ? (d->constant && !d->params.empty()) : cx_.library[callee->index] != Library::kNone;
        if (!constant) return call;
        try {
            FileLoc here = Here();
            Evaluator ev(cx_, nullptr, &here);
            return Num(ev.Eval(call.get(), nullptr));
        } catch (const UserError &) {
            return call;
        }
    }

    Context::Impl &cx_;
    std::string_view s_;
    FileLoc loc_;
    size_t pos_ = 0;
    int line_ = 1;
    const std::vector<std::string> *params_ = nullptr;
    int nesting_ = 0;  // E1, E3 and E4 frames on the stack (Nested)
};

}  // namespace

Context::Context() : impl_(std::make_unique<Impl>()) {
    for (const LibraryEntry &e : kLibrary) impl_->library[impl_->Intern(e.name)] = e.fn;
}

Context::~Context() = default;

void Context::Load(std::string_view text, const FileLoc &loc) {
    Parser p(*impl_, text, loc);
    while (!p.AtEnd()) p.Statement();
}

void Context::AllowOutputChannels(bool allow) { impl_->output_channels = allow; }
void Context::AllowInFunction() { impl_->library[impl_->Intern("in")] = Library::kIn; }

std::vector<std::pair<int, Expression>> Context::OutputChannels() const {
    std::vector<std::pair<int, Expression>> out;
    for (size_t sym = 0; sym < impl_->names.size(); ++sym) {
        const std::string &name = impl_->names[sym];
        if (name.empty() || name[0] != '$' || !impl_->defs[sym]) continue;
        Expression e;  // the channel's variable itself: its definition, evaluated per record
        e.root_ = std::make_unique<Node>();
        e.root_->kind = Node::kVar;
        e.root_->index = static_cast<int>(sym);
        e.text_ = name;
        e.fast_ = SpecialisedExpression::Make(*impl_, e.root_.get(), e.loc_);
        e.fast_context_ = impl_.get();
        e.fast_generation_ = impl_->generation;
        out.emplace_back(std::stoi(name.substr(1)), std::move(e));
    }
    std::sort(out.begin(), out.end(),
              [](const auto &a, const auto &b) { return a.first < b.first; });
    return out;
}

void Context::DefineRayVariables() {
    Load(
        "Dx = $1; Dy = $2; Dz = $3; Nx = $4; Ny = $5; Nz = $6; Px = $7; Py = $8; Pz = $9;"
        "T = $10; Rdot = $11; S = $12; Tx = $13; Ty = $14; Tz = $15; Ix = $16; Iy = $17;"
        "Iz = $18; Jx = $19; Jy = $20; Jz = $21; Kx = $22; Ky = $23; Kz = $24; Ts = $25;"
        "Lu = $26; Lv = $27;",
        FileLoc{"ray variables", 0});
}

void Context::LoadRayInit() {
    DefineRayVariables();
    namespace fs = std::filesystem;
    const fs::path ours = fs::path(DayfluxLibDirectory()) / "rayinit.cal";
    std::error_code ec;
    if (fs::exists(ours, ec)) LoadFile(ours.string());
    const std::string found = FindOnRaypath("rayinit.cal");
    if (!fs::exists(ours, ec) || !fs::equivalent(found, ours, ec)) LoadFile(found);
}

void Context::LoadFile(const std::string &path) {
    std::ifstream f(path);
    if (!f) ErrorExit("cannot open '" + path + "'");
    std::stringstream ss;
    ss << f.rdbuf();
    Load(ss.str(), FileLoc{path, 1});
}

void Context::Set(const std::string &name, double value, bool constant) {
    std::ostringstream s;
    s.precision(17);
    s << name << (constant ? " : " : " = ") << value << ";";
    Load(s.str(), FileLoc{"", 0});
}

Expression Context::CompileInterpreted(std::string_view text, const FileLoc &loc) const {
    Expression e;
    Parser p(*impl_, text, loc);
    e.root_ = p.Expression();
    e.text_ = std::string(text);
    e.loc_ = loc;
    return e;
}

Expression Context::Compile(std::string_view text, const FileLoc &loc) const {
    Expression e = CompileInterpreted(text, loc);
    e.fast_ = SpecialisedExpression::Make(*impl_, e.root_.get(), loc);
    e.fast_context_ = impl_.get();
    e.fast_generation_ = impl_->generation;
    e.direct_ = DirectBins::Recognise(*this, e);
    return e;
}

double Expression::Evaluate(const Context &cx, const Channels *channels) const {
    if (fast_context_ == cx.impl_.get() && fast_generation_ == cx.impl_->generation) {
        if (direct_ && channels) return direct_->Bin(channels);
        if (fast_) return fast_->Evaluate(channels);
    }
    Evaluator ev(*cx.impl_, channels, &loc_);
    return ev.Eval(root_.get(), nullptr);
}

int Context::SymbolIndex(const std::string &name) const {
    auto it = impl_->ids.find(name);
    return it == impl_->ids.end() ? -1 : it->second;
}

const std::string &Context::SymbolName(int index) const { return impl_->names[index]; }

const Context::Definition *Context::Find(int symbol) const {
    return symbol >= 0 && symbol < static_cast<int>(impl_->defs.size()) ? impl_->defs[symbol].get()
                                                                        : nullptr;
}

std::vector<std::string> Context::UndefinedNames(const Expression &e) const {
    const Impl &cx = *impl_;
    std::vector<std::string> undefined;
    std::vector<char> seen(cx.names.size(), 0);
    std::vector<const Node *> todo;  // a stack, not recursion: definitions may chain far
    if (e.Root()) todo.push_back(e.Root());
    while (!todo.empty()) {
        const Node *n = todo.back();
        todo.pop_back();
        for (const NodePtr &kid : n->kids) todo.push_back(kid.get());
        if (n->kind != Node::kVar || seen[n->index]) continue;
        seen[n->index] = 1;
        if (const Definition *d = cx.defs[n->index].get())
            todo.push_back(d->body.get());
        else if (cx.library[n->index] == Library::kNone)
            undefined.push_back(cx.names[n->index]);
    }
    return undefined;
}

double Context::Value(const std::string &name, const Channels *channels) const {
    return Compile(name, FileLoc{"", 0}).Evaluate(*this, channels);
}

}  // namespace dayflux::cal
