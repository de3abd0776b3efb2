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

// The rules of the operations, for folding numbers while the tree is built and for the code's
// run (SpecialisedExpression::Run): one set, so the two give the same numbers.
using Kind = SpecialisedExpression::Kind;
double Arithmetic(Kind k, double a, double b) {
    switch (k) {
        case SpecialisedExpression::kAdd:
            return a + b;
        case SpecialisedExpression::kSub:
            return a - b;
        case SpecialisedExpression::kMul:
            return a * b;
        case SpecialisedExpression::kDiv:  // calcomp's: a zero divisor gives 0
            return b == 0 ? 0 : a / b;
        default:
            return Power(a, b);
    }
}
// select()'s choice among nkids - 1 (0: their count), or its error.
int SelectChoice(double a1, int nkids, const FileLoc &loc) {
    if (!(a1 >= -.5 && a1 + .5 < nkids))
        ErrorExit(&loc, "select: index " + FormatNumber(a1) + " out of range");
    return static_cast<int>(a1 + .5);
}
// max() and min() keep the first of equal values, as the interpreter does.
double Extreme(bool larger, double v, double x) { return (larger ? v < x : v > x) ? x : v; }

// An operation of numbers only: its value (nothing lazy: every operand is already a number).
double FoldNumbers(const SpecialisedExpression::Op &o, const std::vector<double> &v,
                   const FileLoc &loc) {
    switch (o.kind) {
        case SpecialisedExpression::kNeg:
            return -v[0];
        case SpecialisedExpression::kIf:
            return v[0] > 0.0 ? v[1] : v[2];
        case SpecialisedExpression::kSelect: {
            const int n = SelectChoice(v[0], o.nkids, loc);
            return n == 0 ? o.nkids - 1 : v[n];
        }
        case SpecialisedExpression::kMin:
        case SpecialisedExpression::kMax: {
            double x = v[0];
            for (int i = o.nkids - 1; i > 0; --i)
                x = Extreme(o.kind == SpecialisedExpression::kMax, x, v[i]);
            return x;
        }
        case SpecialisedExpression::kMath:
            return LibraryMath(static_cast<Library>(o.fn), v[0], o.nkids > 1 ? v[1] : 0);
        default:
            return Arithmetic(o.kind, v[0], v[1]);
    }
}

}  // namespace

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
    // Adds an operation; one of numbers only becomes its value, by the rules the code runs by.
    int Add(const Op &op, const std::vector<int> &kids) {
        if (kids.empty() || !std::all_of(kids.begin(), kids.end(), [&](int k) { return IsNum(k); }))
            return Append(op, kids);
        std::vector<double> values;
        for (int k : kids) values.push_back(NumOf(k));
        Op o = op;
        o.nkids = static_cast<int32_t>(kids.size());
        return Num(FoldNumbers(o, values, out_.loc_));
    }
    int Append(const Op &op, const std::vector<int> &kids) {
        if (out_.ops_.size() >= kMaxOps) throw NotHandled{};
        Op o = op;
        o.first = static_cast<int32_t>(out_.kids_.size());
        o.nkids = static_cast<int32_t>(kids.size());
        out_.kids_.insert(out_.kids_.end(), kids.begin(), kids.end());
        out_.ops_.push_back(o);
        return static_cast<int>(out_.ops_.size()) - 1;
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
            case Library::kIn:
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
        out->Emit();
    } catch (const NotHandled &) {
        return nullptr;
    } catch (const UserError &) {
        return nullptr;
    }
    return out;
}

// Lays the tree out as code (see Instruction): the root's code, a halt, then each slot's block.
class CodeEmitter {
  public:
    using E = SpecialisedExpression;
    explicit CodeEmitter(E &e) : e_(e), block_(e.slot_roots_.size(), -1) {}

    void EmitAll() {
        Emit(e_.root_);
        Put({E::kIHalt});
        for (size_t k = 0; k < pending_.size(); ++k) {  // blocks may ask for more blocks
            const int slot = pending_[k];
            block_[slot] = Here();
            Emit(e_.slot_roots_[slot]);
            Put({E::kIReturn, 0, 0, slot, e_.slot_roots_[slot]});
        }
        for (const auto &[at, slot] : calls_) e_.code_[at].target = block_[slot];
    }

  private:
    int Here() const { return static_cast<int>(e_.code_.size()); }
    int Put(const E::Instruction &in) {
        e_.code_.push_back(in);
        return Here() - 1;
    }
    int Kid(const E::Op &o, int i) const { return e_.kids_[o.first + i]; }

    void Emit(int id) {
        const E::Op &o = e_.ops_[id];
        switch (o.kind) {
            case E::kNum: {
                E::Instruction in{E::kINum, 0, id};
                in.num = o.num;
                Put(in);
                return;
            }
            case E::kChan:
                Put({E::kIChan, 0, id, o.index});
                return;
            case E::kSlot: {
                if (block_[o.index] == -1) block_[o.index] = -2, pending_.push_back(o.index);
                calls_.emplace_back(Put({E::kICall, 0, id, o.index}), o.index);
                return;
            }
            case E::kAdd:
            case E::kSub:
            case E::kMul:
            case E::kPow: {  // a number operand is the instruction's own (never both: folded)
                const int x = Kid(o, 0), y = Kid(o, 1);
                const int form = IsNum(x) ? 2 : IsNum(y) ? 1 : 0;
                if (form != 2) Emit(x);
                if (form != 1) Emit(y);
                static constexpr E::Code kFirst[] = {E::kIAddRR, E::kISubRR, E::kIMulRR, E::kIHalt,
                                                     E::kIPowRR};
                E::Instruction in{static_cast<E::Code>(kFirst[o.kind - E::kAdd] + form), 0, id, x,
                                  y};
                in.num = form == 2 ? e_.ops_[x].num : form == 1 ? e_.ops_[y].num : 0;
                Put(in);
                return;
            }
            case E::kDiv: {  // a zero divisor gives 0 without evaluating the dividend
                Emit(Kid(o, 1));
                const int test = Put({E::kIZeroDiv, 0, id, 0, Kid(o, 1)});
                Emit(Kid(o, 0));
                Put({E::kIDiv, 0, id, Kid(o, 0), Kid(o, 1)});
                e_.code_[test].target = Here();
                return;
            }
            case E::kNeg:
                Emit(Kid(o, 0));
                Put({E::kINeg, 0, id, Kid(o, 0)});
                return;
            case E::kIf: {
                const int test = Test(Kid(o, 0));
                const int then_end = Branch(id, Kid(o, 1));
                e_.code_[test].target = Here();
                const int else_end = Branch(id, Kid(o, 2));
                e_.code_[then_end].target = e_.code_[else_end].target = Here();
                return;
            }
            case E::kSelect: {
                Emit(Kid(o, 0));
                const int table = static_cast<int>(e_.cases_.size());
                e_.cases_.resize(table + o.nkids - 1);
                const int choose = Put({E::kISelect, 0, id, Kid(o, 0), o.nkids, table});
                std::vector<int> ends;
                for (int n = 1; n < o.nkids; ++n) {
                    e_.cases_[table + n - 1] = Here();
                    ends.push_back(Branch(id, Kid(o, n)));
                }
                for (int at : ends) e_.code_[at].target = Here();
                e_.code_[choose].target = Here();
                return;
            }
            case E::kMin:
            case E::kMax:  // the interpreter's order: the first, then the last back to the second
                Emit(Kid(o, 0));
                Put({E::kIMove, 0, id, Kid(o, 0)});
                for (int i = o.nkids - 1; i > 0; --i) {
                    Emit(Kid(o, i));
                    Put({E::kIMinStep, static_cast<uint8_t>(o.kind == E::kMax), id, Kid(o, i)});
                }
                return;
            case E::kMath:
                Emit(Kid(o, 0));
                if (o.nkids > 1) Emit(Kid(o, 1));
                Put({E::kIMath, o.fn, id, Kid(o, 0), o.nkids > 1 ? Kid(o, 1) : -1});
                return;
        }
    }
    // One way of an if() or select(): its value into dst, then a jump to the end (returned).
    int Branch(int dst, int value) {
        if (IsNum(value)) {
            E::Instruction in{E::kINum, 0, dst};
            in.num = e_.ops_[value].num;
            Put(in);
        } else {
            Emit(value);
            Put({E::kIMove, 0, dst, value});
        }
        return Put({E::kIJump});
    }
    // An if()'s condition and the jump past its first way (returned): a difference with a number
    // (the bins' if(x - c, ...)) tested by one instruction.
    int Test(int cond) {
        const E::Op &o = e_.ops_[cond];
        if (o.kind == E::kSub && (IsNum(Kid(o, 0)) || IsNum(Kid(o, 1)))) {
            const bool above = IsNum(Kid(o, 1));
            const int x = above ? Kid(o, 0) : Kid(o, 1);
            Emit(x);
            E::Instruction in{above ? E::kIJumpUnlessAbove : E::kIJumpUnlessBelow, 0, 0, x};
            in.num = e_.ops_[above ? Kid(o, 1) : Kid(o, 0)].num;
            return Put(in);
        }
        Emit(cond);
        return Put({E::kIJumpUnlessPositive, 0, 0, cond});
    }
    bool IsNum(int id) const { return e_.ops_[id].kind == E::kNum; }

    E &e_;
    std::vector<int> block_;    // each slot's block: -1 not asked for, -2 to be laid out
    std::vector<int> pending_;  // slots in the order their blocks are laid out
    std::vector<std::pair<int, int>> calls_;  // (instruction, slot) to point at their blocks
};

void SpecialisedExpression::Emit() { CodeEmitter(*this).EmitAll(); }

double SpecialisedExpression::Run(const Channels *channels) const {
    constexpr size_t kStackRegisters = 1024;
    double stack_registers[kStackRegisters];
    std::vector<double> heap_registers;
    double *r = stack_registers;
    if (ops_.size() > kStackRegisters) {
        heap_registers.resize(ops_.size());
        r = heap_registers.data();
    }
    double slot[kMaxSlots];
    bool have[kMaxSlots];
    std::memset(have, 0, slot_roots_.size() * sizeof(bool));
    int returns[kMaxSlots + 1];  // a slot's block calls only slots not yet set: at most all
    int depth = 0;
    const Instruction *code = code_.data();
    for (int pc = 0;;) {
        const Instruction &in = code[pc];
        switch (in.code) {
            case kINum:
                r[in.dst] = in.num;
                break;
            case kIChan:
                if (!channels)
                    ErrorExit(&loc_, "ray variable $" + std::to_string(in.a) +
                                         " used where there is no ray");
                r[in.dst] = channels->Value(in.a);
                break;
            case kICall:
                if (!have[in.a]) {
                    returns[depth++] = pc;  // back to this call, which then reads the slot
                    pc = in.target;
                    continue;
                }
                r[in.dst] = slot[in.a];
                break;
            case kIReturn:
                slot[in.a] = r[in.b];
                have[in.a] = true;
                // a return follows its call, which set returns[depth - 1]
                pc = returns[--depth];  // NOLINT(clang-analyzer-core.uninitialized.Assign)
                continue;
            case kIAddRR:
                r[in.dst] = Arithmetic(kAdd, r[in.a], r[in.b]);
                break;
            case kIAddRC:
                r[in.dst] = Arithmetic(kAdd, r[in.a], in.num);
                break;
            case kIAddCR:
                r[in.dst] = Arithmetic(kAdd, in.num, r[in.b]);
                break;
            case kISubRR:
                r[in.dst] = Arithmetic(kSub, r[in.a], r[in.b]);
                break;
            case kISubRC:
                r[in.dst] = Arithmetic(kSub, r[in.a], in.num);
                break;
            case kISubCR:
                r[in.dst] = Arithmetic(kSub, in.num, r[in.b]);
                break;
            case kIMulRR:
                r[in.dst] = Arithmetic(kMul, r[in.a], r[in.b]);
                break;
            case kIMulRC:
                r[in.dst] = Arithmetic(kMul, r[in.a], in.num);
                break;
            case kIMulCR:
                r[in.dst] = Arithmetic(kMul, in.num, r[in.b]);
                break;
            case kIPowRR:
                r[in.dst] = Arithmetic(kPow, r[in.a], r[in.b]);
                break;
            case kIPowRC:
                r[in.dst] = Arithmetic(kPow, r[in.a], in.num);
                break;
            case kIPowCR:
                r[in.dst] = Arithmetic(kPow, in.num, r[in.b]);
                break;
            case kIZeroDiv:
                if (r[in.b] == 0) {
                    r[in.dst] = 0;
                    pc = in.target;
                    continue;
                }
                break;
            case kIDiv:
                r[in.dst] = Arithmetic(kDiv, r[in.a], r[in.b]);
                break;
            case kINeg:
                r[in.dst] = -r[in.a];
                break;
            case kIJumpUnlessPositive:
                if (!(r[in.a] > 0.0)) {
                    pc = in.target;
                    continue;
                }
                break;
            case kIJumpUnlessAbove:
                if (!(r[in.a] - in.num > 0.0)) {
                    pc = in.target;
                    continue;
                }
                break;
            case kIJumpUnlessBelow:
                if (!(in.num - r[in.a] > 0.0)) {
                    pc = in.target;
                    continue;
                }
                break;
            case kIJump:
                pc = in.target;
                continue;
            case kIMove:
                r[in.dst] = r[in.a];
                break;
            case kISelect: {
                const int n = SelectChoice(r[in.a], in.b, loc_);
                if (n == 0) {
                    r[in.dst] = in.b - 1;
                    pc = in.target;
                } else {
                    pc = cases_[in.c + n - 1];
                }
                continue;
            }
            case kIMinStep:
                r[in.dst] = Extreme(in.fn != 0, r[in.dst], r[in.a]);
                break;
            case kIMath:
                r[in.dst] =
                    LibraryMath(static_cast<Library>(in.fn), r[in.a], in.b >= 0 ? r[in.b] : 0);
                break;
            case kIHalt:
                return r[root_];
        }
        ++pc;
    }
}

double SpecialisedExpression::Evaluate(const Channels *channels) const { return Run(channels); }

}  // namespace dayflux::cal
