// Patterns given by functions (brightfunc, colorfunc): their .cal files loaded from RAYPATH into a
// context of their own (after lib/rayinit.cal), evaluated for a ray with the primitive's real
// arguments as A1, A2, ... The sky descriptions of gensky and gendaylit are such patterns.
// Evaluate may be called from many threads: each thread gets its own context (evaluation caches
// values in it).
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "cal/glsl.h"
#include "scene/primitives.h"

namespace dayflux {

class PatternFunction {
  public:
    explicit PatternFunction(const Primitive &pattern);
    // The pattern's RGB factor for a ray: channels hold Dx Dy Dz, Nx Ny Nz, Px Py Pz, ... ($1..).
    void Evaluate(std::span<const double> channels, double rgb[3]) const;
    // The same as GLSL (cal/glsl.h, without the preamble): "void <name>_args()" sets cal_arg to
    // the pattern's arguments, "dvec3 <name>()" (vec3 in float) evaluates it from cal_chan.
    // Throws UserError for what GLSL cannot express.
    std::string Glsl(const std::string &name, cal::GlslPrecision precision) const;

  private:
    struct State {
        std::unique_ptr<cal::Context> cx;
        std::vector<cal::Expression> functions;  // one (brightness) or three (red, green, blue)
    };
    State Load() const;

    Primitive pattern_;
    std::vector<double> args_;
    mutable tbb::enumerable_thread_specific<State> states_;
};

}  // namespace dayflux
