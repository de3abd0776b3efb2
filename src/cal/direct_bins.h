// lib/'s common bin functions computed directly rather than through the calcomp program they
// define: the Klems bins of klems_full.cal, klems_half.cal and klems_quarter.cal (kbin, khbin,
// kqbin: V and D matrices, rfluxmtx's Klems receivers, genBSDF, where the specialised program
// spent 40 % of genBSDF's time) and reinhart.cal's rbin (daylight coefficients, 5 % of a DC
// run). The arithmetic is the .cal files', in their order, with division by a constant done as
// calcomp parses it (times its reciprocal), so the bins are the same. A bin expression is taken
// only where it has that form and gives the expression's bins on a fixed set of directions and
// on the edges of its patches (a file that redefines a helper, RHS, MF or the ray variables
// keeps the calcomp program).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "cal/calcomp.h"

namespace dayflux::cal {

class DirectBins {
  public:
    virtual ~DirectBins() = default;
    // The direct form of e, a bin expression compiled in cx, or nullptr.
    static std::unique_ptr<DirectBins> Recognise(const Context &cx, const Expression &e);
    // The bin of the direction (Dx, Dy, Dz) = ($1, $2, $3).
    double Bin(const Channels *channels) const;
    virtual double Bin(double dx, double dy, double dz) const = 0;

  protected:
    // Directions on the edges of the patches, where an operation taken in another order would
    // round across an edge.
    virtual std::vector<std::array<double, 3>> EdgeDirections() const = 0;
};

// kbin(N, U) and its kin: -1 from behind.
class KlemsBins : public DirectBins {
  public:
    static std::unique_ptr<KlemsBins> Make(const Context &cx, const Expression &e);
    double Bin(double dx, double dy, double dz) const override;

  private:
    std::vector<std::array<double, 3>> EdgeDirections() const override;
    bool RingByCosine(double c, size_t *ring) const;
    double n_[3] = {0, 0, 0};      // the surface normal, toward where rays come from
    double u_[3] = {0, 0, 0};      // the up vector
    double nu_ = 0;                // N . U
    double cross_[3] = {0, 0, 0};  // U x N, as the .cal file forms it
    double minus_rhs_ = -1;
    double per_degree_ = 0;          // 1 / DEGREE
    std::vector<double> upper_;      // ring r's upper polar angle (degrees), r = 1 .. rings
    std::vector<double> cos_upper_;  // its cosine
    bool cosine_rings_ = true;       // whether RingByCosine may decide
    std::vector<double> azimuths_;   // ring r's patches
    std::vector<double> first_;      // bins before ring r
};

// reinhart.cal's rbin at its MF: 0 for the ground.
class ReinhartBins : public DirectBins {
  public:
    static std::unique_ptr<ReinhartBins> Make(const Context &cx, const Expression &e);
    double Bin(double dx, double dy, double dz) const override;

  private:
    std::vector<std::array<double, 3>> EdgeDirections() const override;
    double Patches(double row) const;  // rnaz
    double Below(double row) const;    // raccum
    double mf_ = 1, per_mf_ = 1, per_alpha_ = 0, per_degree_ = 0, alpha_ = 0;
};

}  // namespace dayflux::cal
