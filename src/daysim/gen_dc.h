// gen_dc: DAYSIM's daylight coefficients of a project (.hea). The diffuse run traces the
// sensors under a uniform glowing sphere of luminance 1000 sorted into DAYSIM's 148 patches
// (-Dd), the direct run under the site's ~65 suns of luminance 1000 (-Dm); both with
// rtrace_dc-gpu's engine in this process. Their files (tmp_directory/<variant>.dif.dc and .dir.dc)
// are merged line by line into each shading variant's .dc: 148 diffuse then N direct values.
#pragma once

#include <string>
#include <vector>

#include "daysim/project.h"

namespace dayflux {

struct GenDcOptions {
    bool diffuse = true, direct = true, merge = true;  // -dif, -dir, -paste (all by default)
    bool show_commands = false;                        // -h (DAYSIM's: print the commands)
    std::string extension;                             // -ext: added to the sensor and dc names
    // Ours: passed to rtrace_dc-gpu (-backend, -device, -seed, -n, -gpu_traversal).
    std::vector<std::string> engine_args;
};

void RunGenDc(const DaysimProject &project, const GenDcOptions &options);

}  // namespace dayflux
