// GLSL code generation for calcomp expressions: every definition an expression uses becomes a
// GLSL function in double or single precision (GlslPrecision), so the GPU evaluates the user's own
// bin functions and patterns, not a fixed list. GLSL has no recursion: recursive functions (raccum,
// kfindrow, ...) are unrolled to a fixed depth. GLSL has no double-precision transcendental
// functions either, and its float ones are loose: the generated code carries its own (argument
// reduction and series), accurate to about 1e-15 in double and a few ulps in float.
#pragma once

#include <string>
#include <vector>

#include "cal/calcomp.h"

namespace dayflux::cal {

struct GlslEntry {
    std::string name;        // the GLSL function generated: double (or float) name()
    const Expression *expr;  // evaluated with the channels in cal_chan[1..]
};

// The generated code's real type: double (needs shaderFloat64), or float, for devices without
// it and by default on the GPU (no fp64 in the estimator's hot path).
enum class GlslPrecision { kDouble, kFloat };

struct GlslOptions {
    GlslPrecision precision = GlslPrecision::kDouble;
    int recursion_depth = 64;  // unrolled copies of each recursive function
    int channels = 27;         // size of the channel array (rayinit.cal's $1..$27)
    int max_args = 32;         // object arguments available to arg(n) in cal_arg[1..]
    // Several contexts in one shader (the bins, each pattern): each names its definitions with
    // its own prefix, and only the first emits the shared preamble (cal_chan, cal_arg, the math
    // library).
    std::string prefix = "cal_d";
    bool preamble = true;
};

// GLSL source (no #version line): "double cal_chan[N+1];" (or float) to fill before calling the
// entries, the math library, and one function per entry. Throws UserError for what GLSL cannot
// express (functions passed as arguments), naming the expression.
std::string GenerateGlsl(const Context &cx, const std::vector<GlslEntry> &entries,
                         const GlslOptions &options = {});

}  // namespace dayflux::cal
