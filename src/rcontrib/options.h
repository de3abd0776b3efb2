// rcontrib's command line, read as RADIANCE's rcontrib reads it, and ours beside it: -backend,
// -device and -gpu_* (the engine: IsEngineOption), -seed, -asub, -se (standard errors),
// -target_error and -progress. Options it does not know are errors, as in RADIANCE; options that
// rcontrib forces (-aa 0 -as 0 -dt 0) are accepted and ignored.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "matrix/formats.h"
#include "raytrace/contrib.h"
#include "raytrace/engine.h"

namespace dayflux {

struct CalCommand {
    bool file;  // -f file, else -e expression
    std::string text;
};

struct ModifierSpec {
    TrackedModifier tracked;
    std::string params;  // -p in force
    std::string output;  // -o in force: empty for the standard output
};

struct RcontribOptions {
    ContribOptions contrib;
    std::vector<CalCommand> cal;
    std::vector<ModifierSpec> modifiers;
    DataFormat in = DataFormat::Ascii, out = DataFormat::Ascii;
    bool header = true;
    int accumulate = 1;  // -c
    int xres = 0, yres = 0;
    int threads = 0;
    double report_seconds = 0;  // -t: RADIANCE's progress report every so many seconds
    std::string stderr_file;    // -se (ours): standard errors of the entries, as a matrix
    bool progress = false;      // -progress: a progress line with the time left (ours)
    bool force_open = false;    // -fo: overwrite existing output files
    bool recover = false;       // -r: continue the records of existing output files
    // -first_record (ours): the input's first record is this record of a larger run (a shard),
    // so its random numbers are those the whole run would draw for it; -1: not given.
    long first_record = -1;
    // -sensor_cache ACC (ours): an irradiance cache over the sensors (-I+), rtrace's ambient
    // cache at the sensors with -aa ACC and -ar (raytrace/sensor_cache.h); 0: none (rcontrib's).
    double sensor_cache = 0;
    int ambient_resolution = 256;  // -ar, used by -sensor_cache only
    // -target_error E (ours): each sensor traced in passes until the estimated relative standard
    // error of its illuminance under the reference sky is below E, or its samples reach
    // -max_samples (ours; -ad by default); -target_sky: a sky vector of the columns' weights
    // (uniform by default); -target_report: each sensor's samples and error
    // (raytrace/target_error.h).
    double target_error = 0;
    int max_samples = 0;
    std::string target_sky, target_report;
    EngineOptions engine;  // -backend, -device, -gpu_traversal, -gpu_accum, -gpu_cal
    std::vector<std::string> scene;
};

// -se: every input ray is traced as this many independent replicas with -ad / replicas each;
// their mean is the result and their spread gives its standard error.
constexpr int kReplicas = 8;

// The options (after expanding @file arguments); the arguments that go into output headers are
// appended to args_for_header. The environment's DAYFLUX_BACKEND, DAYFLUX_VULKAN_DEVICE and
// DAYFLUX_GPU_TRAVERSAL are defaults for -backend, -device and -gpu_traversal (ours, for
// pipelines that cannot add options to a command: docs/compat.md).
RcontribOptions ParseRcontribOptions(int argc, char **argv,
                                     std::vector<std::string> *args_for_header);
// The same for a program's arguments as strings (args[0]: its name), as rfluxmtx-gpu builds them.
RcontribOptions ParseRcontribOptions(const std::vector<std::string> &args,
                                     std::vector<std::string> *args_for_header);

// A calcomp context with rayinit.cal, every -e and -f in order, and -p parameters params.
std::unique_ptr<cal::Context> MakeCalContext(const RcontribOptions &o, const std::string &params);

// Whether `option` is one of ours that choose the engine (-backend, -device, -gpu_*: each with
// one value), which the programs building rcontrib's engine pass on to this parser (rfluxmtx-gpu,
// genBSDF, gen_dc, rtrace-gpu and rtrace_dc-gpu): adding one touches the parser and this list.
bool IsEngineOption(const std::string &option);

// The tracked modifiers, each evaluated in the context of the first with the same -p.
std::vector<TrackedModifier> TrackedModifiers(const RcontribOptions &o);

}  // namespace dayflux
