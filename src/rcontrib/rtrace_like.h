// What the rtrace-like programs (rtrace-gpu, rtrace_dc-gpu) share: rtrace's command line read for
// rcontrib's engine (rtrace's defaults, its rendering options passed to rcontrib's parser, and
// those that mean nothing to the engine), the scene's light sources tracked with -V+ so that a
// ray's contributions sum to its radiance, and the engines that trace them (with -aa, irradiance
// sensors through the sensor cache, rtrace's ambient cache at the sensors).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "raytrace/target_error.h"
#include "rcontrib/options.h"
#include "scene/flatten.h"
#include "util/options.h"

namespace dayflux {

// rtrace's ambient cache options: -aa above 0 with -ab asks for the cache.
struct AmbientCacheOptions {
    double accuracy = 0.1;   // -aa
    int resolution = 256;    // -ar
    int supersamples = 512;  // -as
};

// RADIANCE's boolean options: -x+ -x1 -xy -xt set, -x- -x0 -xn -xf clear, -x toggles.
bool RtraceFlag(const std::string &a, bool current);

// The arguments rcontrib's parser gets first: the program's name and rtrace's defaults where
// they differ from rcontrib's.
std::vector<std::string> RtraceDefaults(const std::string &program);

// An option parser for an rtrace-like program: its own options first (Own()), then rtrace's.
class RtraceLikeParser : public OptionCursor {
  public:
    explicit RtraceLikeParser(std::vector<std::string> args) : OptionCursor(std::move(args)) {}
    virtual ~RtraceLikeParser() = default;

    // Reads the options up to the scene, returning the arguments for rcontrib's parser: the
    // defaults, the rendering options and ours, "-V+", a placeholder modifier (the light sources
    // are known once the scene is read) and the scene's files.
    std::vector<std::string> Run();
    const AmbientCacheOptions &Cache() const { return cache_; }

  protected:
    virtual bool Own(const std::string &a) = 0;
    virtual void Usage() const = 0;
    // The program's name, for messages.
    std::string Program() const;
    // Adds an option (with its value) for rcontrib's parser.
    void Pass(const std::string &option, const std::string &value) {
        pass_.insert(pass_.end(), {option, value});
    }

  private:
    bool Ignored(const std::string &a);
    AmbientCacheOptions cache_;
    std::vector<std::string> pass_;
    std::map<std::string, bool> flags_;  // -I -i -ld as given so far
};

// The placeholder Run() passes as -m: RcontribOptions::modifiers holds it until replaced.
extern const char *const kLightSourcesPlaceholder;

// With the ambient cache (-aa > 0) rtrace weighs an ambient sample by the surface's reflectance
// alone, so -lw cuts only deep, dim paths; rcontrib's estimator also divides a sample's weight
// by the sample count, and -lw would cut every ambient ray (with a positive -lr) or play
// roulette with them. So -lw is taken per sample (-lw / -ad) and a positive -lr becomes Russian
// roulette to that depth (docs/compat.md).
void WeighAsWithCache(ContribOptions *c);

// The scene's light sources (light, glow, illum, spotlight materials), by name, once each.
std::vector<std::string> LightSources(const FlatScene &flat);

// -target_error's options from rcontrib's (the sky vector read), and what the run reached: a line
// on stderr, and -target_report's file.
TargetErrorOptions TargetErrorOf(const RcontribOptions &o);
void ReportTargetError(const RcontribOptions &o, const TargetErrorOptions &t,
                       const TargetErrorReport &report);

// The engines a run needs: one for irradiance sensors and one for rays, made when first asked
// (with -target_error, each traces its rays to the target).
class LightEngines {
  public:
    // trace: rendering and engine options (its modifiers are not used); report_cache: the
    // sensor cache's records on stderr.
    LightEngines(const RcontribOptions &trace, const AmbientCacheOptions &cache, bool report_cache,
                 const FlatScene &flat, const std::vector<TrackedModifier> &tracked);
    ContribEngine *For(bool irradiance);
    // -target_error's summary and report, after the run.
    void Finish() const;

    // Traces rays (6 doubles each, numbered from first) into records (`columns` x 3 doubles
    // each), in runs of one engine and at most its batch, in parallel. A ray of zero direction
    // (rtrace's flush) gets a record of zeros. irradiance(k): whether ray k is a sensor (-I).
    void Trace(const std::vector<double> &rays, uint64_t first, int columns,
               const std::function<bool(uint64_t)> &irradiance, std::vector<double> *records);

  private:
    std::unique_ptr<ContribEngine> Create(bool irradiance, bool direct_only,
                                          int divisions = 0) const;

    const RcontribOptions &trace_;
    AmbientCacheOptions cache_;
    bool report_cache_;
    const FlatScene &flat_;
    const std::vector<TrackedModifier> &tracked_;
    std::unique_ptr<ContribEngine> engines_[2];
    TargetErrorOptions target_;
    std::shared_ptr<TargetErrorReport> report_;
};

}  // namespace dayflux
