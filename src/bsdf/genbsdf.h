// RADIANCE's genBSDF with Klems bases: a system's BSDF from its geometry (z <= 0, the room on
// +z), its transmission and reflection from the back (+z, the default) and front (-z, +f) by
// rfluxmtx between a sender just outside the system and two Klems-full glow receivers, as
// genBSDF.pl runs it (-ab 5 -ad 700 -lw 3e-6, then -r's options; -c samples per incident
// patch, on an nx x ny grid over the system's box), turned into WINDOW XML as wrapBSDF -a kf -c
// writes it: photopic Y, transposed, each row divided by its outgoing patch's projected solid
// angle, "%.3e". Tensor trees (-t3, -t4) and MGF input and output are not ours.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

struct GenBsdfOptions {
    int processes = 0;   // -n (0: every core; RADIANCE's genBSDF runs one process by default)
    int samples = 2000;  // -c, before the grid rounds it up
    std::vector<std::string> rfluxmtx_options;  // -r "...", appended to genBSDF's defaults
    bool has_dim = false;                       // -dim xmin xmax ymin ymax zmin zmax
    double dim[6] = {};
    bool forward = false, backward = true;    // +f, -b
    bool colour = false;                      // +C: CIE-X and CIE-Z blocks as well
    bool window6 = false;                     // -W: WINDOW 6's fields
    std::string unit = "meter";               // {+|-}geom unit
    std::vector<std::string> fields;          // -s "x=string;y=string" (wrapBSDF -f)
    std::vector<std::string> inputs;          // scene files ("-" or none: the standard input)
    std::vector<std::string> engine_options;  // ours: -backend, -device, -seed, ...
    std::string command_line;                 // the arguments, for the XML's comment
};

// Parses genBSDF's command line (args[0] the program's name); bad options are UserErrors.
GenBsdfOptions ParseGenBsdfOptions(const std::vector<std::string> &args);

// Runs genBSDF: the XML document (warnings about the system's extent on stderr, as genBSDF's).
std::string GenBsdf(const GenBsdfOptions &options, const std::string &program);

// The Klems-full WINDOW XML of BSDF blocks: each block's type ("tb", "rb", "tf", "rf"), its
// spectrum ("Visible", "CIE-X", "CIE-Z") and its 145 x 145 values, row o (outgoing) column i
// (incident), already divided by the projected solid angles. fields: wrapBSDF -f assignments,
// t w h in `unit`; comment (not empty): an XML comment after the declaration (wrapBSDF -C).
struct BsdfBlock {
    std::string type, spectrum;
    std::vector<double> values;
};
std::string KlemsXml(const std::vector<BsdfBlock> &blocks, const std::vector<std::string> &fields,
                     const std::string &unit, bool window6, const std::string &comment = "");

}  // namespace dayflux
