// rtrace: the radiance along each input ray, or the irradiance at each sensor (-I), with the
// values rtrace's -o asks for, on the contribution engines (the CPU with Embree or a Vulkan GPU):
// a ray's radiance is the sum of every light source's contribution (-V+, rcontrib/rtrace_like.h).
// Without the ambient cache's interpolation: irradiance sensors with -aa above 0 go through the
// sensor cache, and everything else is traced as with -aa 0 (docs/compat.md).
#pragma once

#include <string>
#include <vector>

#include "matrix/formats.h"
#include "rcontrib/options.h"
#include "rcontrib/rtrace_like.h"

namespace dayflux {

struct RtraceOptions {
    RcontribOptions trace;      // the engine, rendering options and scene (rcontrib's parser)
    AmbientCacheOptions cache;  // -aa -ar -as
    std::string outputs = "v";  // -o: what each ray writes (o d v V w W l L p n N s m M ~)
    DataFormat in = DataFormat::Ascii, out = DataFormat::Ascii;  // -f (out RGBE: -fc)
    bool header = true;                                          // -h
    int xres = 0, yres = 0;                                      // -x -y
    std::string error_file;                                      // -e
};

// rtrace's command line (after expanding @file arguments), with rtrace's defaults, and ours (as
// rcontrib-gpu's: -backend, -device, -seed, ...). args[0] is the program's name; header_args
// gets the program and its options, for the header.
RtraceOptions ParseRtraceOptions(const std::vector<std::string> &args,
                                 std::vector<std::string> *header_args);

// Traces the standard input's rays and writes their values to the standard output.
void RunRtrace(const RtraceOptions &o, const std::vector<std::string> &header_args);

}  // namespace dayflux
