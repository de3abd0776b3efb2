// What calcomp.cpp and specialise.cpp share: the library functions and a context's symbols,
// definitions and caches.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "cal/calcomp.h"

namespace dayflux::cal {

enum class Library {
    kNone,
    kAcos,
    kAsin,
    kAtan,
    kAtan2,
    kCeil,
    kCos,
    kExp,
    kFloor,
    kIf,
    kLog,
    kLog10,
    kMax,
    kMin,
    kRand,
    kSelect,
    kSin,
    kSqrt,
    kTan,
    kErf,
    kErfc,
    kArg,
    kIn  // rcalc's in(n): column n of the record, or (n = 0) how many it has
};

// RADIANCE's libfunc() and epow(): a library function's or a power's result that is NaN or
// infinite is a domain or range error, warned of ("sqrt: domain error") and replaced by 0.
// Warned once a process per function here (RADIANCE writes a line a call).
void WarnOfDomainError(Library fn, bool range);
inline double Checked(Library fn, double v) {
    if (std::isfinite(v)) [[likely]]
        return v;
    WarnOfDomainError(fn, !std::isnan(v));
    return 0;
}
// x^y as epow() gives it (kNone stands for the power in the warning).
inline double Power(double x, double y) { return Checked(Library::kNone, std::pow(x, y)); }

// The library's functions of one or two numbers (atan2 takes two; rand is RADIANCE's hash), as
// the C library gives them; LibraryMath() below adds libfunc()'s check of the result.
inline double LibraryMathUnchecked(Library fn, double x, double y) {
    switch (fn) {
        case Library::kRand:
            x *= 1.0 / (1.0 + x * x) + 2.71828182845904;
            x += .785398163397447 - std::floor(x);
            x = 1e5 / x;
            return x - std::floor(x);
        case Library::kAcos:
            return std::acos(x);
        case Library::kAsin:
            return std::asin(x);
        case Library::kAtan:
            return std::atan(x);
        case Library::kAtan2:
            return std::atan2(x, y);
        case Library::kCeil:
            return std::ceil(x);
        case Library::kCos:
            return std::cos(x);
        case Library::kExp:
            return std::exp(x);
        case Library::kFloor:
            return std::floor(x);
        case Library::kLog:
            return std::log(x);
        case Library::kLog10:
            return std::log10(x);
        case Library::kSin:
            return std::sin(x);
        case Library::kSqrt:
            return std::sqrt(x);
        case Library::kTan:
            return std::tan(x);
        case Library::kErf:
            return std::erf(x);
        case Library::kErfc:
            return std::erfc(x);
        default:
            return 0;  // not a function of numbers alone: the callers do not ask
    }
}
inline double LibraryMath(Library fn, double x, double y = 0) {
    return Checked(fn, LibraryMathUnchecked(fn, x, y));
}

struct Context::Impl {
    std::vector<std::string> names;
    std::unordered_map<std::string, int> ids;
    std::vector<std::unique_ptr<Definition>> defs;
    std::vector<Library> library;
    // Cached values of constant (':') variables, filled on first use.
    mutable std::vector<char> have_constant;
    mutable std::vector<double> constant_value;
    // Values of the other variables within one evaluation (one ray): a variable depends only on
    // channels and other variables, so it is computed once per top-level Evaluate.
    mutable std::vector<uint64_t> variable_epoch;
    mutable std::vector<double> variable_value;
    mutable uint64_t epoch = 1;
    bool output_channels = false;  // "$N = e;" definitions allowed (rcalc)

    int Intern(const std::string &raw) {
        std::string name = raw;
        while (name.size() > 1 && name.back() == '`') name.pop_back();  // "x`" is the global x
        auto it = ids.find(name);
        if (it != ids.end()) return it->second;
        const int id = static_cast<int>(names.size());
        names.push_back(name);
        ids.emplace(name, id);
        defs.emplace_back();
        library.push_back(Library::kNone);
        have_constant.push_back(0);
        constant_value.push_back(0);
        variable_epoch.push_back(0);
        variable_value.push_back(0);
        return id;
    }
    // Definitions changed: constants are computed again, and specialised programs
    // (specialise.h) made before are stale.
    void Invalidate() {
        std::fill(have_constant.begin(), have_constant.end(), 0);
        ++generation;
    }
    uint64_t generation = 0;
};

}  // namespace dayflux::cal
