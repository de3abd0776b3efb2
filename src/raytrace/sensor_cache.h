// An irradiance cache over a run's sensors, as rtrace's ambient cache (Ward et al. 1988) would
// fill it at the sensors themselves: where a sensor lies close to another one's record, its
// indirect light is interpolated from the records near it instead of traced. DAYSIM's rtrace_dc
// keeps such a cache (-aa, -ar) with a vector of coefficients in every record; here a record is a
// traced sensor's whole record (every bin), so no light is lost and nothing is approximated but
// the interpolation. Made in passes, the same on every engine and thread count:
//   1. each sensor's record radius: the harmonic mean distance of a small hemisphere of rays,
//      clamped to [size / -ar, 64 size / -ar] (size: the scene's extent), as rtrace's;
//   2. in sensor order, a sensor becomes a record unless an earlier record covers it: Ward's
//      error |P - Pi| / Ri + sqrt(1 - N.Ni) below -aa, the record not in front of it;
//   3. the records are traced by the engine (on a GPU, all at once), and every sensor's direct
//      light (-ab 0) too, since light sources are never interpolated;
//   4. every other sensor: its own direct light plus the records' indirect light (whole record
//      minus its direct part), weighted by 1 / error over the records that cover it.
// Only the sensors' own level is cached (rtrace also caches deeper bounces).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "raytrace/backend.h"
#include "raytrace/engine.h"
#include "scene/flatten.h"

namespace dayflux {

struct SensorCacheOptions {
    double accuracy = 0.1;  // -aa
    int resolution = 256;   // -ar (0: radii not clamped)
    int radius_rays = 64;   // hemisphere rays per sensor for its radius
    uint64_t seed = 0;
};

struct SensorCacheStats {
    size_t sensors = 0, records = 0;
};

// Traces n sensors (origin and normal, 6 doubles each; sensor i's random numbers keyed by
// keys[i], its index in the run) into records (engine.Columns() x 3 doubles each), with `full`
// (the run's engine, -I+) and `direct` (the same scene and bins with -ab 0).
// A zero direction is no sensor: its record stays 0. replica: as ContribEngine::Trace's.
// caster: the scene committed to a CPU ray caster (for the records' radii).
SensorCacheStats TraceWithSensorCache(ContribEngine &full, ContribEngine &direct,
                                      const FlatScene &scene, const Backend &caster,
                                      const double *rays, size_t n,
                                      const uint64_t *keys, int replica,
                                      const SensorCacheOptions &options, double *records);

// An engine that traces each batch of sensors (BatchRays(): thousands) through the cache, the
// records of a batch shared by its sensors only: for rcontrib-gpu's -sensor_cache (ours) and
// rtrace_dc-gpu's -aa. It overwrites the records it is given (it is for one ray a record). The
// scene must outlive it;
// report: the records made of how many sensors, summed over the batches, on stderr at the end.
std::unique_ptr<ContribEngine> WithSensorCache(std::unique_ptr<ContribEngine> full,
                                               std::unique_ptr<ContribEngine> direct,
                                               const FlatScene &scene,
                                               const SensorCacheOptions &options, bool report);

}  // namespace dayflux
