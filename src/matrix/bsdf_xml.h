// Klems BSDF XML files (WINDOW 6 / LBNL format) as the matrices the three- and five-phase
// methods multiply: element (out r, in c) = (BSDF + Lambertian part) x projected solid angle of
// incident patch c, with RADIANCE's front/back swap and reciprocity rules.
#pragma once

#include <string>
#include <vector>

#include "matrix/matrices.h"

namespace dayflux {

// An angle basis: latitude rings between theta bounds, each with nphis azimuth patches.
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

}  // namespace dayflux
