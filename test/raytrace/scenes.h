// Small scenes shared by the integrator tests of both backends.
#pragma once

#include <array>
#include <cmath>
#include <sstream>
#include <string>

namespace dayflux::test {

// The six faces of the box [lo, hi] as RADIANCE polygons of modifier mod named name0..name5,
// their normals outward (written out rather than made with genbox, so the tests need only
// dayflux).
inline std::string BoxOfPolygons(const std::string &mod, const std::string &name,
                                 const std::array<double, 3> &lo, const std::array<double, 3> &hi) {
    // Each face's corners, a bit per axis: 0 at lo, 1 at hi.
    static const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    std::ostringstream box;
    for (int f = 0; f < 6; ++f) {
        box << mod << " polygon " << name << f << " 0 0 12";
        for (int c : faces[f])
            for (int k = 0; k < 3; ++k) box << " " << ((c >> k & 1) ? hi[k] : lo[k]);
        box << "\n";
    }
    return box.str();
}

// View factor from a point to a parallel rectangle of half-widths a, b centred above it at
// height c: four times the corner formula.
inline double ParallelRectangleViewFactor(double a, double b, double c) {
    const double X = a / c, Y = b / c;
    return 4 *
           (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
            Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
           (2 * M_PI);
}

// A closed 2 m cube around the origin.
inline std::string CubeOfPolygons(const std::string &mod) {
    return BoxOfPolygons(mod, "f", {-1, -1, -1}, {1, 1, 1});
}

// A closed 5 x 4 x 3 m room of white plastic under a glow sky (`skyglow`), a 2 km ground plane
// 10 m below it: the scene is large, the room must stay dark.
inline std::string ClosedRoomInALargeScene() {
    return "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 360\n"
           "void plastic white 0 0 5 .8 .8 .8 0 0\n" +
           BoxOfPolygons("white", "room", {0, 0, 0}, {5, 4, 3}) +
           "void plastic gnd 0 0 5 .2 .2 .2 0 0\n"
           "gnd polygon ground 0 0 12 -1e3 -1e3 -10 1e3 -1e3 -10 1e3 1e3 -10 -1e3 1e3 -10\n";
}

// A 5 x 4 x 3 m room of grey plastic `wall` whose wall at y = 0 has a 3 x 1 m window of illum
// `winillum` (radiance 2, void behind it).
inline std::string IllumWindowRoom() {
    return "void plastic wall 0 0 5 .5 .5 .5 0 0\n"
           "wall polygon floor 0 0 12  0 0 0  0 4 0  5 4 0  5 0 0\n"
           "wall polygon ceil 0 0 12  0 0 3  5 0 3  5 4 3  0 4 3\n"
           "wall polygon w1a 0 0 12  0 0 0  5 0 0  5 0 1  0 0 1\n"
           "wall polygon w1b 0 0 12  0 0 2  5 0 2  5 0 3  0 0 3\n"
           "wall polygon w1c 0 0 12  0 0 1  1 0 1  1 0 2  0 0 2\n"
           "wall polygon w1d 0 0 12  4 0 1  5 0 1  5 0 2  4 0 2\n"
           "wall polygon w2 0 0 12  5 0 0  5 4 0  5 4 3  5 0 3\n"
           "wall polygon w3 0 0 12  5 4 0  0 4 0  0 4 3  5 4 3\n"
           "wall polygon w4 0 0 12  0 4 0  0 0 0  0 0 3  0 4 3\n"
           "void illum winillum 0 0 3 2 2 2\n"
           "winillum polygon win 0 0 12  1 0 1  1 0 2  4 0 2  4 0 1\n";
}

// A Klems Full BSDF file of a Lambertian layer: every transmission entry tau / pi and every
// reflection entry rho / pi (both sides), so that it transmits tau and reflects rho of any
// incident light, spread by the cosine (the bins' projected solid angles sum to pi).
inline std::string LambertianKlemsXml(double tau, double rho) {
    std::ostringstream x;
    x.precision(17);
    x << "<?xml version=\"1.0\"?>\n<WindowElement><FileType>BSDF</FileType><Optical><Layer>\n"
      << "<DataDefinition><IncidentDataStructure>Columns</IncidentDataStructure>"
      << "</DataDefinition>\n";
    for (const char *block :
         {"Transmission Front", "Transmission Back", "Reflection Front", "Reflection Back"}) {
        const double value = (block[0] == 'T' ? tau : rho) / M_PI;
        x << "<WavelengthData><Wavelength>Visible</Wavelength><WavelengthDataBlock>"
          << "<WavelengthDataDirection>" << block << "</WavelengthDataDirection>"
          << "<ColumnAngleBasis>LBNL/Klems Full</ColumnAngleBasis>"
          << "<RowAngleBasis>LBNL/Klems Full</RowAngleBasis><ScatteringData>";
        for (int k = 0; k < 145 * 145; ++k) x << (k ? ", " : "") << value;
        x << "</ScatteringData></WavelengthDataBlock></WavelengthData>\n";
    }
    x << "</Layer></Optical></WindowElement>\n";
    return x.str();
}

}  // namespace dayflux::test
