// Patterns given by functions (brightfunc, colorfunc): their .cal files loaded from RAYPATH into a
// context of their own (after lib/rayinit.cal), evaluated for a ray with the primitive's real
// arguments as A1, A2, ... The sky descriptions of gensky and gendaylit are such patterns.
#pragma once

#include <memory>
#include <string>

#include "cal/calcomp.h"
#include "scene/primitives.h"

namespace dayflux {

class PatternFunction {
  public:
    explicit PatternFunction(const Primitive &pattern);
    // The pattern's RGB factor for a ray: channels hold Dx Dy Dz, Nx Ny Nz, Px Py Pz, ... ($1..).
    void Evaluate(const std::vector<double> &channels, double rgb[3]) const;
    const cal::Context &Context() const { return *cx_; }
    const std::vector<cal::Expression> &Functions() const { return functions_; }

  private:
    std::unique_ptr<cal::Context> cx_;
    std::vector<cal::Expression> functions_;  // one (brightness) or three (red, green, blue)
    std::vector<double> args_;
};

}  // namespace dayflux
