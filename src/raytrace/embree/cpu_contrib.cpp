#include "raytrace/embree/cpu_contrib.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <utility>

#include "raytrace/backend.h"
#include "raytrace/core/random.h"
#include "raytrace/core/sampling.h"
#include "raytrace/core/shapes.h"
#include "raytrace/core/tables.h"
#include "util/errors.h"

namespace dayflux {
namespace core {

// A thread's room for CpuScene::BlockedAhead: the rays it asks, their sources, the answers.
struct AheadBuffers {
    std::vector<TraceRay> rays;
    std::vector<int> sources;
    std::unique_ptr<bool[]> blocked;
    size_t capacity = 0;
};

// What a thread's estimator shares with the others: the scene, its tables and the run's options,
// and what they report (the core's kReport* flags, items dropped), for the engine.
struct CpuScene {
    const FlatScene &flat;
    const PackedScene &packed;
    const Backend &backend;
    const ContribOptions &options;
    const std::vector<TrackedModifier> &tracked;
    const MakeContext &make_context;
    std::atomic<uint32_t> &reports;
    std::atomic<uint64_t> &dropped;
    bool has_blockers = false;

    // The core's ray (recentred) for the backend, in world coordinates.
    TraceRay RayFrom(const real3 &org, const real3 &dir, int from) const {
        TraceRay tr;
        for (int k = 0; k < 3; ++k) tr.org[k] = org[k] + packed.centre[k], tr.dir[k] = dir[k];
        tr.tmax = std::numeric_limits<double>::infinity();
        tr.from_object = from;
        return tr;
    }

    // The blockers on the shadow rays from org toward sources first .. end - 1 that ask them
    // (ShadowRaysAskBlockers), at their centres (without -dj, where direct.inl's shadow rays go),
    // asked at once, on the sides of normal that the direct item shades (front, back): ahead[i]
    // 2 where blocked, 1 where not, 0 where not asked. Returns false where it asks nothing (no
    // blockers, or -dj).
    bool BlockedAhead(real3 org, real3 normal, int from, bool front, bool back, int first, int end,
                      uint8_t *ahead, AheadBuffers *buffers) const {
        if (!has_blockers || options.source_jitter > kTiny) return false;
        std::vector<TraceRay> *rays = &buffers->rays;
        std::vector<int> *which = &buffers->sources;
        rays->clear();
        which->clear();
        for (int i = first; i < end; ++i) {
            ahead[i] = 0;
            const PackedSource &s = packed.sources[i];
            if (!ShadowRaysAskBlockers(s)) continue;
            const real3 dir = XYZ(s.dir);
            const real ldot = dot(normal, dir);
            if (!((front && ldot > kTiny) || (back && ldot < -kTiny))) continue;
            rays->push_back(RayFrom(org, dir, from));
            which->push_back(i);
        }
        if (buffers->capacity < rays->size()) {
            buffers->blocked.reset(new bool[rays->size()]);
            buffers->capacity = rays->size();
        }
        backend.Blocked(rays->data(), buffers->blocked.get(), rays->size());
        for (size_t k = 0; k < rays->size(); ++k) ahead[(*which)[k]] = buffers->blocked[k] ? 2 : 1;
        return true;
    }

    // Whether a blocker lies on the ray (the backend's, committed with the scene).
    bool Blocked(real3 org, real3 dir, int from) const {
        const TraceRay tr = RayFrom(org, dir, from);
        bool blocked = false;
        backend.Blocked(&tr, &blocked, 1);
        return blocked;
    }

    // Pattern k for the ray variables $1..$27 in channels[1..27] (the calcomp interpreter).
    real3 PatternRGB(int k, const double *channels) const {
        double rgb[3];
        packed.patterns[k]->Evaluate(std::span<const double>(channels + 1, 27), rgb);
        return real3(rgb[0], rgb[1], rgb[2]);
    }
};

// A thread's bins: the tracked modifiers' bin expressions in the calcomp contexts they are
// evaluated in (each thread has its own, since evaluation caches values), each expression
// compiled once per context (-M: thousands of modifiers may share one).
class CpuBins {
  public:
    explicit CpuBins(const CpuScene &s) : source_bins_(s.packed.sources.size()) {
        std::map<std::pair<const cal::Context *, std::string>, size_t> compiled;
        for (size_t k = 0; k < s.tracked.size(); ++k) {
            const int of = s.tracked[k].context_of;
            if (of < 0) {
                own_contexts_.push_back(s.make_context(static_cast<int>(k)));
                contexts_.push_back(own_contexts_.back().get());
            } else {
                contexts_.push_back(contexts_[of]);
            }
            const std::string &text = s.tracked[k].bin_expression;
            auto [it, added] =
                compiled.emplace(std::make_pair(contexts_.back(), text), bins_.size());
            if (added) bins_.push_back(contexts_.back()->Compile(text, FileLoc{"-b", 0}));
            bin_of_.push_back(it->second);
        }
    }

    // Tracked modifier k's bin value for the ray variables in channels[1..27]. A ray reaching
    // a distant source (source >= 0) has variables that depend on its direction only, and
    // shadow rays with -dj 0 (sun coefficients) reach each source in one direction, so a
    // source's last value is remembered with the direction and modifier it was for.
    double Value(int k, int source, const double *channels) {
        SourceBin *memo = source >= 0 ? &source_bins_[source] : nullptr;
        if (memo && memo->tracked == k && memo->dir[0] == channels[1] &&
            memo->dir[1] == channels[2] && memo->dir[2] == channels[3])
            return memo->value;
        const cal::ChannelView view(std::span<const double>(channels + 1, 27));
        const double value = bins_[bin_of_[k]].Evaluate(*contexts_[k], &view);
        if (memo) *memo = SourceBin{{channels[1], channels[2], channels[3]}, k, value};
        return value;
    }

  private:
    std::vector<std::unique_ptr<cal::Context>> own_contexts_;
    std::vector<cal::Context *> contexts_;  // per tracked modifier, maybe shared
    std::vector<cal::Expression> bins_;     // the distinct ones
    std::vector<size_t> bin_of_;            // per tracked modifier
    struct SourceBin {
        double dir[3];
        int tracked = -1;
        double value = 0;
    };
    std::vector<SourceBin> source_bins_;
};

class CpuEstimator {
  public:
    virtual ~CpuEstimator() = default;
    // Adds the contributions of input ray `index` (replica `replica`) to records, a record for
    // each of its first hemisphere's `slices` slices (as walk.inl's InputCells shares out the
    // rows, with shares of the light sources): the hemisphere is traced whole, not replayed a
    // slice at a time.
    virtual void Trace(const double org[3], const double dir[3], uint64_t index, int replica,
                       double *records, int slices = 1) = 0;
};

// The estimator compiled three times: for scenes with none of the core's features (daylight,
// view and sun matrices through glass: the common case), with -asub alone, and with all of them.
#define DAYFLUX_ESTIMATOR PlainEstimator
#include "raytrace/embree/cpu_estimator.inl"
#undef DAYFLUX_ESTIMATOR

#define DAYFLUX_ASUB 1
#define DAYFLUX_ESTIMATOR SubsampledEstimator
#include "raytrace/embree/cpu_estimator.inl"
#undef DAYFLUX_ESTIMATOR

#define DAYFLUX_BSDF 1
#define DAYFLUX_DIELECTRIC 1
#define DAYFLUX_LOCAL_SOURCES 1
#define DAYFLUX_MIRROR_IMAGES 1
#define DAYFLUX_INSIDE 1
#define DAYFLUX_APERTURE 1
#define DAYFLUX_ESTIMATOR FullEstimator
#include "raytrace/embree/cpu_estimator.inl"
#undef DAYFLUX_ESTIMATOR

}  // namespace core

namespace {

class CpuContribEngine : public ContribEngine {
  public:
    CpuContribEngine(const FlatScene &flat, std::vector<TrackedModifier> tracked,
                     std::unique_ptr<SceneMaterials> table, PackedScene packed,
                     const ContribOptions &options, const MakeContext &make_context,
                     std::unique_ptr<Backend> backend, int paths)
        : tracked_(std::move(tracked)),
          table_(std::move(table)),
          packed_(std::move(packed)),
          options_(options),
          make_context_(make_context),
          backend_(std::move(backend)),
          scene_{flat, packed_, *backend_, options_, tracked_, make_context_, reports_, dropped_},
          paths_(paths) {
        if (packed_.mix_depth > 63)
            ErrorExit("mixfuncs nested more than 63 deep (" + packed_.mix_deepest + ")");
        std::vector<uint32_t> blockers = Blockers(flat, packed_);
        scene_.has_blockers = !blockers.empty();
        backend_->SetBlockers(std::move(blockers));
        backend_->Commit(flat);
    }

    std::string Label() const override { return backend_->Name(); }
    int Columns() const override { return packed_.columns; }
    // Small batches: one sensor ray can cost millions of rays.
    size_t BatchRays() const override { return 2; }

    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) override {
        const size_t record = 3 * static_cast<size_t>(packed_.columns);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            const double *r = rays + 6 * i;
            if (r[3] == 0 && r[4] == 0 && r[5] == 0) return;  // counts, contributes nothing
            std::unique_ptr<core::CpuEstimator> &e = estimators_.local();
            if (!e) e = MakeEstimator();
            e->Trace(r, r + 3, first_index + i, replica, records + i * record);
        });
        WarnCoreReports(reports_.exchange(0), dropped_.exchange(0));
    }

    bool TraceSlices(const double *rays, size_t n, const uint64_t *keys, int replica, int slices,
                     double *slice_records) override {
        CHECK(slices >= 1);
        // (a task a ray, its hemisphere whole: -target_error gives a batch's rays a few at a
        // time, but many batches run at once; a run of fewer sensors than threads leaves
        // threads idle)
        const size_t record = 3 * static_cast<size_t>(packed_.columns);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            const double *r = rays + 6 * i;
            if (r[3] == 0 && r[4] == 0 && r[5] == 0) return;
            std::unique_ptr<core::CpuEstimator> &e = estimators_.local();
            if (!e) e = MakeEstimator();
            e->Trace(r, r + 3, keys[i], replica, slice_records + i * record * size_t(slices),
                     slices);
        });
        WarnCoreReports(reports_.exchange(0), dropped_.exchange(0));
        return true;
    }

  private:
    // The triangles that stop every shadow ray (core::StopsShadowRays), where shadow rays go
    // to distant sources (direct.inl's ShadowRay): none where a dielectric could bend a shadow ray
    // or antimatter's inside material change what a surface is.
    static std::vector<uint32_t> Blockers(const FlatScene &flat, const PackedScene &p) {
        std::vector<uint32_t> blockers;
        const bool suns = std::any_of(p.sources.begin(), p.sources.end(),
                                      [](const auto &s) { return core::ShadowRaysAskBlockers(s); });
        if (!suns || p.dielectric || p.inside) return blockers;
        for (size_t t = 0; t < flat.triangles.size(); ++t)
            if (core::StopsShadowRays(p.surfaces[p.triangles[t].surface]))
                blockers.push_back(static_cast<uint32_t>(t));
        return blockers;
    }

    // The estimator with only the features the scene needs.
    std::unique_ptr<core::CpuEstimator> MakeEstimator() const {
        const PackedScene &p = packed_;
        if (p.bsdf || p.dielectric || p.local_sources || p.mirror_images || p.inside)
            return std::make_unique<core::FullEstimator>(scene_, paths_);
        if (options_.ambient_subsamples > 1)
            return std::make_unique<core::SubsampledEstimator>(scene_, paths_);
        return std::make_unique<core::PlainEstimator>(scene_, paths_);
    }

    std::vector<TrackedModifier> tracked_;
    std::unique_ptr<SceneMaterials> table_;
    PackedScene packed_;
    ContribOptions options_;
    MakeContext make_context_;
    std::unique_ptr<Backend> backend_;
    std::atomic<uint32_t> reports_{0};
    std::atomic<uint64_t> dropped_{0};
    core::CpuScene scene_;
    int paths_;  // EngineOptions::cpu_paths_at_once
    tbb::enumerable_thread_specific<std::unique_ptr<core::CpuEstimator>> estimators_;
};

}  // namespace

std::unique_ptr<ContribEngine> CreateCpuContribEngine(
    const FlatScene &scene, std::vector<TrackedModifier> tracked,
    std::unique_ptr<SceneMaterials> table, PackedScene packed, const ContribOptions &options,
    const MakeContext &make_context, std::unique_ptr<Backend> backend, int paths_at_once) {
    return std::make_unique<CpuContribEngine>(scene, std::move(tracked), std::move(table),
                                              std::move(packed), options, make_context,
                                              std::move(backend), paths_at_once);
}

}  // namespace dayflux
