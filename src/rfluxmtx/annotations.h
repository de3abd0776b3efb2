// rfluxmtx's sender and receiver files: RADIANCE scene files whose `#@rfluxmtx` comment lines
// give the parameters of the surfaces after them (h= the hemisphere's basis, u= the up vector,
// o= a receiver's output file), read as RADIANCE's rfluxmtx reads them (src/util/rfluxmtx.c):
// polygons, rings and (receivers only) sources count, grouped by modifier; other objects are
// skipped; `!command` lines are run and read. Bad input is reported with file and line.
#pragma once

#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {

// A hemisphere's basis as h= names it: u (uniform: one bin), kf kh kq (Klems full, half,
// quarter), rN (Reinhart with N subdivisions; t: Tregenza, r1), scN (Shirley-Chiu N x N).
struct FluxBasis {
    enum Kind { kUniform, kKlemsFull, kKlemsHalf, kKlemsQuarter, kReinhart, kShirleyChiu } kind;
    int size = 1;              // N of rN and scN
    bool left_handed = false;  // a leading '-' on h=
    std::string spec;          // as written after h= (without the sign)
};

// A polygon, ring or source of a sender or receiver.
struct FluxSurface {
    enum Type { kPolygon, kRing, kSource } type;
    std::string name;
    std::vector<double> args;  // its real arguments
    double normal[3];          // unit (a source's: its direction reversed)
    double area;               // a source's: its projected solid angle
    FileLoc loc;
};

// The surfaces of one modifier with the parameters in force where they began.
struct FluxGroup {
    std::string modifier;
    bool has_basis = false;
    FluxBasis basis;
    double up[3] = {0, 0, 0};  // zero: unset
    std::string output;        // o=
    std::vector<FluxSurface> surfaces;
    FileLoc loc;  // where the group's first surface is
    // The area-weighted normal (unit), the up vector (given, else Z where the normal is not
    // within 45 degrees of it, else Y), for the hemisphere's frame. Errors (at the group's first
    // surface) where there is no normal or the up vector given is along it.
    void Normal(double n[3]) const;
    void Up(double u[3]) const;
};

// The receivers of a file (and the files its !commands give), one group per modifier in order.
std::vector<FluxGroup> ReadReceivers(const std::string &path);

// The sender of a file: one group (RADIANCE warns when its surfaces have several modifiers).
FluxGroup ReadSender(const std::string &path);

}  // namespace dayflux
