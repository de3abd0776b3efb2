// Small scenes shared by the integrator tests of both backends.
#pragma once

#include <string>

namespace dayflux::test {

// The six faces of a closed 2 m cube around the origin as RADIANCE polygons of modifier mod
// (written out rather than made with genbox, so the tests need only dayflux).
inline std::string CubeOfPolygons(const std::string &mod) {
    static const char *const faces[6] = {
        "-1 -1 -1  -1 1 -1  1 1 -1  1 -1 -1", "-1 -1 1  1 -1 1  1 1 1  -1 1 1",
        "-1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1", "-1 1 -1  -1 1 1  1 1 1  1 1 -1",
        "-1 -1 -1  -1 -1 1  -1 1 1  -1 1 -1", "1 -1 -1  1 1 -1  1 1 1  1 -1 1"};
    std::string box;
    for (int f = 0; f < 6; ++f)
        box += mod + " polygon f" + std::to_string(f) + " 0 0 12 " + faces[f] + "\n";
    return box;
}

}  // namespace dayflux::test
