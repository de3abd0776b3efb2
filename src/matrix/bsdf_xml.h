// Klems BSDF XML files (WINDOW 6 / LBNL format) as the matrices the three- and five-phase
// methods multiply: element (out r, in c) = (BSDF + Lambertian part) x projected solid angle of
// incident patch c, with RADIANCE's front/back swap and reciprocity rules.
#pragma once

#include <string>
#include <vector>

#include "matrix/matrices.h"

namespace dayflux {

// An angle basis: latitude rings between theta bounds, each with nphis azimuth patches.
// Patches an angle basis may have: Klems full has 145; RADIANCE's own limit is 1000 (MAXLATS
// rings aside), so 100000 leaves room and keeps a basis's matrix within memory.
constexpr int kMaxBasisSize = 100000;

struct AngleBasis {
    std::string name;
    std::vector<double> theta;  // ring bounds in degrees, theta[0] = 0, size = rings + 1
    std::vector<int> nphis;     // patches per ring
    int Size() const;
    // Projected solid angle of patch i (RADIANCE's io_getohm()).
    double ProjectedSolidAngle(int i) const;
    // Patch index of a direction in the basis's own frame (z up), -1 when below the horizon.
    int IndexOf(double x, double y, double z) const;
    // Centre direction of patch i (z up).
    void Centre(int i, double v[3]) const;
};

// The built-in LBNL/Klems Full (145), Half (73) and Quarter (41) bases.
const std::vector<AngleBasis> &KlemsBases();

// Loads the transmission (rmtxop default, dctimestep T) or a reflection matrix from a Klems
// BSDF XML file. Tensor-tree files are refused with a message saying so.
ColorMatrix LoadBsdfMatrix(const std::string &path, BsdfPart part);

// A Klems BSDF as RADIANCE's BSDF library holds it for ray tracing (bsdf_m.c), for the BSDF
// material: per side and direction, the matrix of values (out o, in i) with the Lambertian
// minimum taken out, and the Lambertian parts as hemispherical totals (cieY). Front and back
// are RADIANCE's: XML "Transmission Front" is `tb`, "Reflection Front" is `rb`. Only the
// Visible (CIE-Y) channel is kept: colour data are traced grey.
struct KlemsComponent {
    AngleBasis in, out;         // empty (no patches) where the part has no non-diffuse data
    std::vector<float> values;  // [o * in.Size() + i]
    double max_hemi = 0;        // largest hemispherical total over incident patches
    bool present() const { return !values.empty(); }
};
struct KlemsBsdf {
    KlemsComponent rf, rb, tf, tb;
    double r_lamb_front = 0, r_lamb_back = 0, t_lamb_front = 0, t_lamb_back = 0;
};
KlemsBsdf LoadKlemsBsdf(const std::string &path);

}  // namespace dayflux
