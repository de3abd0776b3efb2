// rtrace_dc: DAYSIM's rtrace, which gives each input ray (a sensor) N daylight coefficients
// instead of a radiance: the light it finds, sorted by the light source's modifier name (-Dm:
// `solarK` is coefficient K-1, the direct run's suns) or by the direction it came from (-Dd:
// DAYSIM's 148 sky and ground patches, daysim/patches.h, the diffuse run's sky), divided by the
// sources' luminance -L. Traced by the contribution engines (raytrace/engine.h) with -V+.
#pragma once

#include <string>
#include <vector>

#include "matrix/formats.h"
#include "rcontrib/options.h"
#include "rcontrib/rtrace_like.h"
#include "util/files.h"

namespace dayflux {

struct RtraceDcOptions {
    RcontribOptions trace;           // the engine, rendering options and scene (rcontrib's parser)
    int coefficients = 0;            // -N
    bool by_direction = false;       // -Dd, else -Dm
    double source_luminance = 1000;  // -L
    // -U n u1 .. un: 1 irradiance, else radiance, per sensor; empty: -I for all.
    std::vector<int> sensor_units;
    bool header = true;                                          // -h
    DataFormat in = DataFormat::Ascii, out = DataFormat::Ascii;  // -f
    // -aa -ar -as: the ambient cache's accuracy, resolution and super-samples (-aa 0: no cache).
    AmbientCacheOptions cache;
    bool report_cache = false;  // -cache_report (ours): the sensor cache's records on stderr
};

// rtrace_dc's command line (after expanding @file arguments): rtrace's options with rtrace's
// defaults, DAYSIM's (-N -Dm -Dd -L -U -oc) and ours (as rcontrib-gpu's: -backend, -device,
// -seed, ...). args[0] is the program's name; header_args gets the arguments for the header.
RtraceDcOptions ParseRtraceDcOptions(const std::vector<std::string> &args,
                                     std::vector<std::string> *header_args);

// Traces the rays of `rays` (a file, "-" for the standard input, or "!command") and writes each
// one's coefficients (ascii: N values "%e\t" and a newline; -ff/-fd: N floats or doubles) to out,
// or to the standard output when out is null. A given out is left for the caller to commit.
// Returns the number of rays.
size_t RunRtraceDc(const RtraceDcOptions &o, const std::vector<std::string> &header_args,
                   const std::string &rays = "-", OutputFile *out = nullptr);

}  // namespace dayflux
