// An expression specialised to its context, for the hot path (bin functions and patterns run at
// every ray hit): calls of the context's functions inlined, their arguments bound to slots that
// are computed on first use and remembered for one evaluation (as the interpreter's frames do),
// variables that do not depend on the ray folded to numbers, if() and select() with constant
// conditions reduced to the branch taken, and the tree laid out flat. It performs the
// interpreter's operations in the interpreter's order (no algebraic rewriting), so it gives the
// same numbers, without frames and symbol look-ups.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "cal/calcomp.h"

namespace dayflux::cal {

class SpecialisedExpression {
  public:
    // nullptr where the expression needs what this does not handle (recursion, functions passed
    // as arguments, arg(), undefined names, errors found while folding): the interpreter
    // evaluates those, and reports their errors.
    static std::unique_ptr<SpecialisedExpression> Make(const Context::Impl &cx, const Node *root,
                                                       const FileLoc &loc);
    double Evaluate(const Channels *channels) const;

    enum Kind : uint8_t {
        kNum,
        kChan,
        kSlot,
        kAdd,
        kSub,
        kMul,
        kDiv,
        kPow,
        kNeg,
        kIf,
        kSelect,
        kMin,
        kMax,
        kMath
    };
    struct Op {
        Kind kind = kNum;
        uint8_t fn = 0;     // kMath: the library function
        int32_t nkids = 0;  // operands: kids_[first .. first + nkids - 1]
        int32_t first = 0;
        int32_t index = 0;  // kChan: the channel; kSlot: the slot
        double num = 0;
    };
    static constexpr int kMaxSlots = 256;

  private:
    friend class SpecialisationBuilder;
    friend class CodeEmitter;
    // The tree as straight-line code over registers (one per operation), run by Evaluate without
    // recursion: if(), select() and a division's zero test jump, and each slot's expression is a
    // block called on its first use, so the code grows with the operations, not with their uses.
    enum Code : uint8_t {
        kINum,     // r[dst] = num
        kIChan,    // r[dst] = channel a
        kICall,    // r[dst] = slot a, running its block at `target` first if it is not set
        kIReturn,  // slot a = r[b]; back to the call
        // r[dst] = r[a] op r[b] (RR), r[a] op num (RC) or num op r[b] (CR)
        kIAddRR,
        kIAddRC,
        kIAddCR,
        kISubRR,
        kISubRC,
        kISubCR,
        kIMulRR,
        kIMulRC,
        kIMulCR,
        kIPowRR,
        kIPowRC,
        kIPowCR,
        kIZeroDiv,  // if r[b] == 0: r[dst] = 0, go to target
        kIDiv,      // r[dst] = r[a] / r[b]
        kINeg,
        kIJumpUnlessPositive,  // if !(r[a] > 0) go to target
        kIJumpUnlessAbove,     // if !(r[a] - num > 0) go to target (if(x - c, ...))
        kIJumpUnlessBelow,     // if !(num - r[a] > 0) go to target (if(c - x, ...))
        kIJump,
        kIMove,     // r[dst] = r[a]
        kISelect,   // r[a] picks among the b - 1 choices (0 gives b - 1), case n at cases_[c + n -
                    // 1]
        kIMinStep,  // r[dst] = the smaller of r[dst] and r[a] (fn 1: the larger)
        kIMath,     // r[dst] = LibraryMath(fn, r[a], b >= 0 ? r[b] : 0)
        kIHalt
    };
    struct Instruction {
        Code code = kIHalt;
        uint8_t fn = 0;
        int32_t dst = 0, a = 0, b = 0, c = 0, target = 0;
        double num = 0;
    };
    void Emit();
    double Run(const Channels *channels) const;

    std::vector<Op> ops_;
    std::vector<int32_t> kids_;
    std::vector<int32_t> slot_roots_;  // each slot's expression
    int32_t root_ = 0;
    std::vector<Instruction> code_;
    std::vector<int32_t> cases_;  // select()'s jump tables
    FileLoc loc_;
};

}  // namespace dayflux::cal
