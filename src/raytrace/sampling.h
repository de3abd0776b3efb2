// Sampling maps shared by the integrators (and by the tests that predict where samples land).
#pragma once

#include <cmath>

namespace dayflux {

// Shirley-Chiu: unit square to unit disk, area-preserving (RADIANCE's square2disk()).
inline void SquareToDisk(double sx, double sy, double *dx, double *dy) {
    const double a = 2 * sx - 1, b = 2 * sy - 1;
    double r, phi;
    if (a > -b) {
        if (a > b)
            r = a, phi = M_PI / 4 * (b / a);
        else
            r = b, phi = M_PI / 4 * (2 - a / b);
    } else {
        if (a < b)
            r = -a, phi = M_PI / 4 * (4 + b / a);
        else
            r = -b, phi = b != 0 ? M_PI / 4 * (6 - a / b) : 0;
    }
    *dx = r * std::cos(phi);
    *dy = r * std::sin(phi);
}

}  // namespace dayflux
