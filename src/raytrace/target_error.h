// -target_error (ours): each input ray (a sensor) traced in passes of growing sample counts until
// the estimated relative standard error of its illuminance under a reference sky falls below the
// target, or its samples reach the cap. A pass of a sensor (-I) traces its first hemisphere
// twice, a pair of replicas whose grids turn alike (core/random.h's kPairedReplicas), in slices
// of rows: the pair's differences, slice by slice, estimate the error of the pass's mean without
// giving up the hemisphere's stratification. A pass of another ray (and of an engine without
// slices) traces it as 8 independent replicas, whose spread estimates the error. The passes are
// combined weighted by their samples.
// Every decision rests on the ray's own samples, whose random numbers are keyed by the ray's
// index, the pass and the replica: the result is the same for any thread count, device split or
// sharding.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "raytrace/engine.h"

namespace dayflux {

struct TargetErrorOptions {
    double target = 0;    // the relative standard error to reach
    int max_samples = 0;  // the cap: first-hemisphere samples a ray may take (rcontrib's -ad)
    // Each column's weight in the reference illuminance (a sky vector's luminance per bin);
    // empty: every column 1 (a uniform sky over the matrix's columns).
    std::vector<double> weights;
    bool sensors = false;  // -I: the rays are sensors, whose first hemispheres can be sliced
};

// What each ray reached, kept for the report (rays from any thread, in any order).
class TargetErrorReport {
  public:
    struct Ray {
        uint64_t index;
        int samples;
        double error;    // estimated relative standard error (0 for a dark ray)
        bool at_target;  // stopped on its error's bound, not at the cap
    };
    void Add(const std::vector<Ray> &rays);
    // Sorted by index.
    std::vector<Ray> Rays() const;
    // "N of M sensors at the target, K at the cap (S samples), the worst error E %".
    std::string Summary(const TargetErrorOptions &o) const;

  private:
    mutable std::mutex mutex_;
    std::vector<Ray> rays_;
};

// make_engine(divisions): an engine of the run's scene and options with -ad divisions.
using EngineMaker = std::function<std::unique_ptr<ContribEngine>(int divisions)>;

// An engine whose Trace() does the passes; the records it adds are each ray's combined mean.
std::unique_ptr<ContribEngine> WithTargetError(EngineMaker make_engine,
                                               const TargetErrorOptions &options,
                                               std::shared_ptr<TargetErrorReport> report);

}  // namespace dayflux
