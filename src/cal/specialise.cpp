#include "cal/specialise.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "cal/calcomp_impl.h"
#include "util/strings.h"

namespace dayflux::cal {

namespace {

struct NotHandled {};  // the interpreter keeps the expression

constexpr int kMaxInlineDepth = 64;
constexpr size_t kMaxOps = 1 << 16;  // inlining copies bodies per call: bound what it may grow to
static_assert(Node::kSub == Node::kAdd + 1 && Node::kMul == Node::kAdd + 2 &&
              Node::kDiv == Node::kAdd + 3 && Node::kPow == Node::kAdd + 4);

}  // namespace

// One evaluation: the slots' values and which are set.
struct SpecialisedRun {
    SpecialisedRun(const SpecialisedExpression &ex, const Channels *ch) : e(ex), channels(ch) {
        std::memset(have, 0, e.slot_roots_.size() * sizeof(bool));
    }
    const SpecialisedExpression &e;
    const Channels *channels;
    double value[SpecialisedExpression::kMaxSlots];  // read only where `have` says it was set
    bool have[SpecialisedExpression::kMaxSlots];

    double Kid(const SpecialisedExpression::Op &o, int i) { return Eval(e.kids_[o.first + i]); }

    double Eval(int id) {
        const SpecialisedExpression::Op &o = e.ops_[id];
        switch (o.kind) {
            case SpecialisedExpression::kNum:
                return o.num;
            case SpecialisedExpression::kChan:
                if (!channels)
                    ErrorExit(&e.loc_, "ray variable $" + std::to_string(o.index) +
                                           " used where there is no ray");
                return channels->Value(o.index);
            case SpecialisedExpression::kSlot:
                if (!have[o.index]) {
                    value[o.index] = Eval(e.slot_roots_[o.index]);
                    have[o.index] = true;
                }
                return value[o.index];
            case SpecialisedExpression::kAdd:
                return Kid(o, 0) + Kid(o, 1);
            case SpecialisedExpression::kSub:
                return Kid(o, 0) - Kid(o, 1);
            case SpecialisedExpression::kMul:
                return Kid(o, 0) * Kid(o, 1);
            case SpecialisedExpression::kDiv: {
                const double d = Kid(o, 1);
                if (d == 0) return 0;
                return Kid(o, 0) / d;
            }
            case SpecialisedExpression::kPow:
                return std::pow(Kid(o, 0), Kid(o, 1));
            case SpecialisedExpression::kNeg:
                return -Kid(o, 0);
            case SpecialisedExpression::kIf:
                return Kid(o, 0) > 0.0 ? Kid(o, 1) : Kid(o, 2);
            case SpecialisedExpression::kSelect: {
                const double a1 = Kid(o, 0);
                if (!(a1 >= -.5 && a1 + .5 < o.nkids))
                    ErrorExit(&e.loc_, "select: index " + FormatNumber(a1) + " out of range");
                const int n = static_cast<int>(a1 + .5);
                if (n == 0) return o.nkids - 1;
                return Kid(o, n);
            }
            case SpecialisedExpression::kMin:
            case SpecialisedExpression::kMax: {
                double v = Kid(o, 0);
                for (int i = o.nkids - 1; i > 0; --i) {
                    const double x = Kid(o, i);
                    if (o.kind == SpecialisedExpression::kMax ? v < x : v > x) v = x;
                }
                return v;
            }
            case SpecialisedExpression::kMath: {
                const double a = Kid(o, 0);
                return LibraryMath(static_cast<Library>(o.fn), a, o.nkids > 1 ? Kid(o, 1) : 0);
            }
        }
        return 0;
    }
};

class SpecialisationBuilder {
  public:
    using Op = SpecialisedExpression::Op;
    using Kind = SpecialisedExpression::Kind;

    SpecialisationBuilder(const Context::Impl &cx, SpecialisedExpression &out)
        : cx_(cx), out_(out), var_node_(cx.names.size(), -1), active_(cx.names.size(), 0) {}

    int Spec(const Node *n, const std::vector<int> &env) {
        switch (n->kind) {
            case Node::kNum:
                return Num(n->num);
            case Node::kArg:
                if (n->index < 1 || n->index > static_cast<int>(env.size())) throw NotHandled{};
                return env[n->index - 1];
            case Node::kChan: {
                Op op;
                op.kind = SpecialisedExpression::kChan;
                op.index = n->index;
                return Add(op, {});
            }
            case Node::kVar:
                return Variable(n->index);
            case Node::kCall:
                return Call(n, env);
            case Node::kNeg:
                return Add(Op{SpecialisedExpression::kNeg}, {Spec(n->kids[0].get(), env)});
            default: {
                static constexpr Kind kinds[] = {
                    SpecialisedExpression::kAdd, SpecialisedExpression::kSub,
                    SpecialisedExpression::kMul, SpecialisedExpression::kDiv,
                    SpecialisedExpression::kPow};
                const int a = Spec(n->kids[0].get(), env), b = Spec(n->kids[1].get(), env);
                return Add(Op{kinds[n->kind - Node::kAdd]}, {a, b});
            }
        }
    }

  private:
    // Adds an operation; one of numbers only becomes its value, computed by the evaluator
    // itself (so folding and evaluation share one set of rules).
    int Add(const Op &op, const std::vector<int> &kids) {
        if (out_.ops_.size() >= kMaxOps) throw NotHandled{};
        Op o = op;
        o.first = static_cast<int32_t>(out_.kids_.size());
        o.nkids = static_cast<int32_t>(kids.size());
        out_.kids_.insert(out_.kids_.end(), kids.begin(), kids.end());
        out_.ops_.push_back(o);
        const int id = static_cast<int>(out_.ops_.size()) - 1;
        if (kids.empty() || !std::all_of(kids.begin(), kids.end(), [&](int k) { return IsNum(k); }))
            return id;
        const double v = SpecialisedRun(out_, nullptr).Eval(id);
        out_.ops_.pop_back();
        out_.kids_.resize(o.first);
        return Num(v);
    }
    int Num(double v) {
        Op op;
        op.num = v;
        return Add(op, {});
    }
    bool IsNum(int id) const { return out_.ops_[id].kind == SpecialisedExpression::kNum; }
    double NumOf(int id) const { return out_.ops_[id].num; }
    // Numbers, channels and slots are cheap to use twice; anything else gets a slot.
    int Shared(int id) {
        const Kind k = out_.ops_[id].kind;
        if (k == SpecialisedExpression::kNum || k == SpecialisedExpression::kChan ||
            k == SpecialisedExpression::kSlot)
            return id;
        if (out_.slot_roots_.size() >= SpecialisedExpression::kMaxSlots) throw NotHandled{};
        Op op;
        op.kind = SpecialisedExpression::kSlot;
        op.index = static_cast<int32_t>(out_.slot_roots_.size());
        out_.slot_roots_.push_back(id);
        return Add(op, {});
    }

    // A variable is computed once per evaluation (the interpreter's cache), or is a number.
    int Variable(int sym) {
        if (var_node_[sym] >= 0) return var_node_[sym];
        const Context::Definition *d = cx_.defs[sym].get();
        if (!d || !d->params.empty() || active_[sym]) throw NotHandled{};
        active_[sym] = 1;
        const int body = Spec(d->body.get(), {});
        active_[sym] = 0;
        return var_node_[sym] = Shared(body);
    }

    int Call(const Node *n, const std::vector<int> &env) {
        const Node *callee = n->kids[0].get();
        if (callee->kind != Node::kVar) throw NotHandled{};  // a function passed as an argument
        const int sym = callee->index;
        const int nargs = static_cast<int>(n->kids.size()) - 1;
        const Context::Definition *d = cx_.defs[sym].get();
        if (!d) return LibraryCall(cx_.library[sym], n, env);
        if (d->params.empty() || nargs < static_cast<int>(d->params.size()) || active_[sym] ||
            depth_ >= kMaxInlineDepth)
            throw NotHandled{};
        std::vector<int> args(nargs);
        for (int i = 0; i < nargs; ++i) args[i] = Shared(Spec(n->kids[i + 1].get(), env));
        active_[sym] = 1;
        ++depth_;
        const int body = Spec(d->body.get(), args);
        --depth_;
        active_[sym] = 0;
        return body;
    }

    int LibraryCall(Library fn, const Node *n, const std::vector<int> &env) {
        const int nargs = static_cast<int>(n->kids.size()) - 1;
        const auto arg = [&](int i) { return Spec(n->kids[i].get(), env); };
        switch (fn) {
            case Library::kIf: {
                if (nargs < 3) throw NotHandled{};
                const int c = arg(1);
                if (IsNum(c)) return arg(NumOf(c) > 0.0 ? 2 : 3);
                const int a = arg(2), b = arg(3);
                return Add(Op{SpecialisedExpression::kIf}, {c, a, b});
            }
            case Library::kSelect: {
                if (nargs < 1) throw NotHandled{};
                const int c = arg(1);
                if (IsNum(c)) {
                    const double a1 = NumOf(c);
                    if (!(a1 >= -.5 && a1 + .5 < nargs))
                        throw NotHandled{};  // the interpreter's error
                    const int i = static_cast<int>(a1 + .5);
                    return i == 0 ? Num(nargs - 1) : arg(i + 1);
                }
                std::vector<int> kids{c};
                for (int i = 2; i <= nargs; ++i) kids.push_back(arg(i));
                return Add(Op{SpecialisedExpression::kSelect}, kids);
            }
            case Library::kMin:
            case Library::kMax: {
                if (nargs < 1) throw NotHandled{};
                std::vector<int> kids;
                for (int i = 1; i <= nargs; ++i) kids.push_back(arg(i));
                return Add(Op{fn == Library::kMax ? SpecialisedExpression::kMax
                                                  : SpecialisedExpression::kMin},
                           kids);
            }
            case Library::kNone:
            case Library::kArg:
                throw NotHandled{};
            default: {
                const int arity = fn == Library::kAtan2 ? 2 : 1;
                if (nargs < arity) throw NotHandled{};
                Op op{SpecialisedExpression::kMath};
                op.fn = static_cast<uint8_t>(fn);
                return arity == 1 ? Add(op, {arg(1)}) : Add(op, {arg(1), arg(2)});
            }
        }
    }

    const Context::Impl &cx_;
    SpecialisedExpression &out_;
    std::vector<int> var_node_;  // per symbol: its node, once made
    std::vector<char> active_;   // per symbol: being expanded (recursion is not inlined)
    int depth_ = 0;
};

std::unique_ptr<SpecialisedExpression> SpecialisedExpression::Make(const Context::Impl &cx,
                                                                   const Node *root,
                                                                   const FileLoc &loc) {
    auto out = std::make_unique<SpecialisedExpression>();
    out->loc_ = loc;
    try {
        SpecialisationBuilder b(cx, *out);
        out->root_ = b.Spec(root, {});
    } catch (const NotHandled &) {
        return nullptr;
    } catch (const UserError &) {
        return nullptr;
    }
    return out;
}

double SpecialisedExpression::Evaluate(const Channels *channels) const {
    SpecialisedRun run(*this, channels);
    return run.Eval(root_);
}

}  // namespace dayflux::cal
