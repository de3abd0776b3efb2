// The Klems bin functions of lib/klems_full.cal, klems_half.cal and klems_quarter.cal (kbin,
// khbin, kqbin), computed directly rather than through the calcomp program they define: a V or
// D matrix, rfluxmtx's Klems receivers and genBSDF evaluate one at nearly every ray's end, where
// the specialised program spent 40 % of genBSDF's time. The arithmetic is the .cal files', in
// their order, so the bins are the same; a call is taken only where its arguments are numbers
// and its bins equal the expression's on a fixed set of directions (a file that redefines a
// helper, RHS or the ray variables keeps the calcomp program).
#pragma once

#include <memory>
#include <vector>

#include "cal/calcomp.h"

namespace dayflux::cal {

class KlemsBins {
  public:
    // The direct form of e, a bin expression compiled in cx, or nullptr.
    static std::unique_ptr<KlemsBins> Recognise(const Context &cx, const Expression &e);
    // The bin of the direction (Dx, Dy, Dz) = ($1, $2, $3), or -1 from behind.
    double Bin(const Channels *channels) const;
    double Bin(double dx, double dy, double dz) const;

  private:
    double n_[3] = {0, 0, 0};      // the surface normal, toward where rays come from
    double u_[3] = {0, 0, 0};      // the up vector
    double nu_ = 0;                // N . U
    double cross_[3] = {0, 0, 0};  // U x N, as the .cal file forms it
    double minus_rhs_ = -1;
    double per_degree_ = 0;         // 1 / DEGREE
    std::vector<double> upper_;     // ring r's upper polar angle (degrees), r = 1 .. rings
    std::vector<double> azimuths_;  // ring r's patches
    std::vector<double> first_;     // bins before ring r
};

}  // namespace dayflux::cal
