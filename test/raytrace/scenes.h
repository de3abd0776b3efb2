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

// ---- Feature scenes, written once for both engines: contrib_test.cpp traces each on Embree
// against RADIANCE 5.4's numbers (or an analytic answer), vulkan_contrib_test.cpp on Vulkan
// against Embree.

// A sun of radiance 1 (modifier `solar`) at altitude alt (radians), its azimuth along +y.
inline std::string SunScene(double alt) {
    std::ostringstream sun;
    sun.precision(17);
    sun << "void light solar 0 0 3 1 1 1\nsolar source sun 0 0 4 0 " << std::cos(alt) << " "
        << std::sin(alt) << " 0.533\n";
    return sun.str();
}

// A sun (`solar`, radiance 1, toward sun_dir) and a sky of radiance 1 (`skyglow`) over a 10 x 10
// x 0.3 m slab of grey dielectric water (index 1.33) from z = 1 to 1.3.
inline const double kSlabSun[3] = {0.3, 0.5, 0.8};
inline std::string DielectricSlab() {
    std::ostringstream scene;
    scene.precision(17);
    scene << "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n"
          << "void light solar 0 0 3 1 1 1\nsolar source sun 0 0 4 " << kSlabSun[0] << " "
          << kSlabSun[1] << " " << kSlabSun[2]
          << " 0.533\nvoid dielectric water 0 0 5 .9 .85 .8 1.33 0\n";
    const double z0 = 1, z1 = 1.3, h = 5;
    const double box[6][4][3] = {{{-h, -h, z1}, {h, -h, z1}, {h, h, z1}, {-h, h, z1}},
                                 {{-h, -h, z0}, {-h, h, z0}, {h, h, z0}, {h, -h, z0}},
                                 {{-h, -h, z0}, {h, -h, z0}, {h, -h, z1}, {-h, -h, z1}},
                                 {{h, -h, z0}, {h, h, z0}, {h, h, z1}, {h, -h, z1}},
                                 {{h, h, z0}, {-h, h, z0}, {-h, h, z1}, {h, h, z1}},
                                 {{-h, h, z0}, {-h, -h, z0}, {-h, -h, z1}, {-h, h, z1}}};
    for (int f = 0; f < 6; ++f) {
        scene << "water polygon f" << f << " 0 0 12";
        for (const auto &v : box[f]) scene << " " << v[0] << " " << v[1] << " " << v[2];
        scene << "\n";
    }
    return scene.str();
}

// A sun (`solar`, radiance 1, at 40 degrees) and a sky of radiance .2 (`skyglow`) over a 100 m
// floor of rough metal (roughness .2, its Gaussian sampled) or, with metal false, of plastic
// whose specularity .015 lies below -st .02 (folded into the diffuse part).
inline std::string RoughFloor(bool metal) {
    return SunScene(40 * M_PI / 180) +
           "void glow skyglow 0 0 4 .2 .2 .2 0\nskyglow source sky 0 0 4 0 0 1 180\n" +
           (metal ? "void metal f 0 0 5 .6 .5 .4 .8 .2\n"
                  : "void plastic f 0 0 5 .5 .4 .3 .015 .1\n") +
           "f polygon floor 0 0 12 -50 -50 0 50 -50 0 50 50 0 -50 50 0\n";
}

// mixfunc: a floor half white, half black (mix.cal's `side`: its x), under a grey screen that is
// black plastic for .3 of it and void (the sky through it) for the rest, under a sky of radiance
// 1 (`skyglow`). The files mix.cal and mix.rad.
inline const char *kMixCal = "side = if(Px, 1, A1);\nscr = .3;\n";
inline std::string MixfuncHalvesAndScreen() {
    return "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n"
           "void plastic white 0 0 5 .8 .8 .8 0 0\n"
           "void plastic black 0 0 5 0 0 0 0 0\n"
           "void mixfunc halves 4 white black side mix.cal 0 1 .5\n"
           "void mixfunc screen 4 black void scr mix.cal 0 0\n"
           "halves polygon floor 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n"
           "screen polygon shade 0 0 12 -1 -1 2 -1 1 2 1 1 2 1 -1 2\n";
}

// A closed 5 x 4 x 3 m room of grey plastic lit by local sources facing down from its ceiling: a
// square panel and a hexagon of `lamp` (the hexagon sampled over a square of its area, which
// RADIANCE turns at random), a sphere (`bulb`) and a disc (`disc`, a ring).
inline std::string LocalSourcesRoom() {
    return "void plastic wall 0 0 5 .5 .5 .5 0 0\n"
           "wall polygon floor 0 0 12  0 0 0  0 4 0  5 4 0  5 0 0\n"
           "wall polygon ceil 0 0 12  0 0 3  5 0 3  5 4 3  0 4 3\n"
           "wall polygon w1 0 0 12  0 0 0  5 0 0  5 0 3  0 0 3\n"
           "wall polygon w2 0 0 12  5 0 0  5 4 0  5 4 3  5 0 3\n"
           "wall polygon w3 0 0 12  5 4 0  0 4 0  0 4 3  5 4 3\n"
           "wall polygon w4 0 0 12  0 4 0  0 0 0  0 0 3  0 4 3\n"
           "void light lamp 0 0 3 100 100 100\n"
           "lamp polygon panel 0 0 12  2 1.5 2.99  2 2.5 2.99  3 2.5 2.99  3 1.5 2.99\n"
           "void light bulb 0 0 3 50 50 50\n"
           "bulb sphere b1 0 0 4  1 1 2 0.1\n"
           "void light disc 0 0 3 80 80 80\n"
           "disc ring r1 0 0 8  4 3 2.99  0 0 -1  0 0.2\n"
           "lamp polygon hex 0 0 18  3.7 1.2 2.99  3.7 1.5 2.99  4 1.7 2.99  4.3 1.5 2.99  4.3 "
           "1.2 2.99  4 1 2.99\n";
}

// A sun (`solar`, radiance 1, at 50 degrees) and a 40-degree glow patch (`skyglow`, radiance
// .2) on the other side of the zenith, above the horizontal sheets below.
inline std::string SunAndPatch() {
    return SunScene(50 * M_PI / 180) +
           "void glow skyglow 0 0 4 .2 .2 .2 0\nskyglow source sky 0 0 4 0 -.5 .866 40\n";
}

// A 100 m sheet at z = 1 of `material`, whose modifier is `w`.
inline std::string Sheet(const std::string &material) {
    return material + "\nw polygon sheet 0 0 12 -50 -50 1 50 -50 1 50 50 1 -50 50 1\n";
}

// Frosted trans sheets (roughness .15): transmission sampled about the ray's direction, with a
// diffuse part too (a); below -st (.5 x .03), folded into the hemisphere behind (b); and below
// -st with no diffuse transmission, where only the lobe toward a source passes (c).
inline std::string FrostedSheet(char which) {
    return Sheet(which == 'a'   ? "void trans w 0 0 7 .8 .7 .6 .05 .15 .9 .8"
                 : which == 'b' ? "void trans w 0 0 7 .8 .7 .6 0 .15 .5 .03"
                                : "void trans w 0 0 7 .8 .7 .6 0 .15 .02 1");
}

// An aBSDF sheet of Klems data `xml` (clear glass: a strong peak; or a fabric with some
// openness: a peak and a surround).
inline std::string ApertureSheet(const std::string &xml) {
    return Sheet("void aBSDF w 5 " + xml + " 0 1 0 . 0 0");
}

}  // namespace dayflux::test
