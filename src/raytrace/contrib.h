// rcontrib's estimator: the ray tree RADIANCE traces from each input ray, with every ray carrying
// the product of the coefficients above it; where a ray reaches an object whose modifier is
// tracked (-m), that coefficient (times the object's radiance with -V+) is added to the bin the
// modifier's bin expression gives. Ambient hemispheres are n x n cosine-stratified with
// n = sqrt(ad * min(weight, 0.8 rho weight / (ad lw))) as RADIANCE computes them with -aa 0;
// Russian roulette follows -lr and -lw. Diffuse surfaces sample distant `light` sources directly,
// as RADIANCE's direct() does with rcontrib's forced -dt 0: one shadow ray per source in front of
// the surface, carrying dirnorm()'s coefficient, passing through glass. Random numbers come from a
// counter-based generator keyed by (seed, input ray), so results do not depend on the number of
// threads.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "raytrace/backend.h"
#include "scene/flatten.h"
#include "scene/patterns.h"

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
    int ambient_subsamples = 1;      // -asub N (ours): N x N samples per first-hemisphere cell
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

class ContribIntegrator {
  public:
    // make_context builds, for tracked modifier k, a context with every -e/-f and k's -p applied;
    // it is called once per thread for each modifier with a context of its own, since
    // evaluation caches constants.
    ContribIntegrator(const FlatScene &scene, const Backend &backend, const ContribOptions &options,
                      std::vector<TrackedModifier> tracked,
                      std::function<std::unique_ptr<cal::Context>(int)> make_context);
    ~ContribIntegrator();

    int Columns() const { return columns_; }
    // Adds the contributions of one input ray to record (Columns() x 3 values). ray_index keys
    // the random numbers.
    void Trace(const double org[3], const double dir[3], uint64_t ray_index, double *record) const;

    struct Impl;

  private:
    std::unique_ptr<Impl> impl_;
    int columns_ = 0;
};

}  // namespace dayflux
