// rcontrib's estimator, as the engines run it (raytrace/engine.h, the core in raytrace/core):
// the ray tree RADIANCE traces from each input ray, with every ray carrying the product of the
// coefficients above it; where a ray reaches an object whose modifier is tracked (-m), that
// coefficient (times the object's radiance with -V+) is added to the bin the modifier's bin
// expression gives. This file holds what a run asks of it: the options and the tracked
// modifiers.
#pragma once

#include <cstdint>
#include <string>

namespace dayflux {

struct ContribOptions {
    int ambient_bounces = 1;            // -ab
    int ambient_divisions = 350;        // -ad
    double limit_weight = 2e-3;         // -lw
    int limit_reflections = -10;        // -lr
    bool irradiance = false;            // -I: input rays are points and normals of sensors
    bool first_hit_irradiance = false;  // -i
    bool contributions = false;         // -V+
    double specular_threshold = 0.02;   // -st: rough specular below it joins the diffuse part
    double specular_jitter = 1.0;       // -ss
    double source_jitter = 0.9;      // -dj (rcontrib's default): shadow rays spread over a source
    double source_size_ratio = 0.2;  // -ds: local sources split where larger than this x distance
    int direct_relays = 3;           // -dr (rcontrib's default): mirrors a source is seen through
    int ambient_subsamples = 1;      // -asub N (ours): N x N samples per first-hemisphere cell,
                                     // receivers sampled below it
    uint64_t seed = 0;
};

// One -m: its name, bin expression, bin count and the calcomp context it is evaluated in.
struct TrackedModifier {
    std::string name;
    std::string bin_expression = "0";
    int nbins = 1;
    int first_column = 0;  // its first bin's position in an output record
    // An earlier modifier whose context this one's bins are evaluated in (the same -p
    // parameters), or -1 for a context of its own.
    int context_of = -1;
};

}  // namespace dayflux
