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
    friend struct SpecialisedRun;
    std::vector<Op> ops_;
    std::vector<int32_t> kids_;
    std::vector<int32_t> slot_roots_;  // each slot's expression
    int32_t root_ = 0;
    FileLoc loc_;
};

}  // namespace dayflux::cal
