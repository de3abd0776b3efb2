#include "raytrace/target_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "raytrace/core/random.h"
#include "util/errors.h"

namespace dayflux {

namespace {

constexpr int kPassReplicas = 8;  // replicas per pass (rays that are not sensors)
constexpr int kMaxSlices = 32;    // slices of a pair's hemispheres: the error's degrees of freedom
constexpr size_t kSliceBytes = size_t(64) << 20;  // the slices' records held at once

// The first pass's samples: a 64th of the cap, at least 8 per replica. No ray stops after its
// first pass: its error rests on two at least (a first estimate that came out low by chance sent
// sensors 5-8 times their estimate out).
int FirstPassSamples(int cap) { return std::min(cap, std::max(8 * kPassReplicas, cap / 64)); }

// A pass's result for each of its rays: the mean record, and its illuminance's mean and variance.
struct PassResult {
    std::vector<double> records;         // rays x width
    std::vector<double> entry_variance;  // rays x width: each entry's mean's variance
    std::vector<double> mean, variance;
    // the variance's effective degrees of freedom: few where a few slices hold most of it
    std::vector<double> dof;
};

// The factor that takes an estimated standard error with `dof` degrees of freedom to a bound it
// stays under with 84 % confidence (one standard deviation of a normal; Wilson and Hilferty's
// cube root of the chi-square's quantile). A sensor stops on that bound, not on the estimate:
// where a few slices hold the variance, the estimate scatters widely, and stopping on its
// first low draw left sensors 5-8 times their estimate out.
double UpperBoundFactor(double dof) {
    if (!(dof > 0)) return 1;
    // (dof is at least 1, where q is 0.31: the floor only keeps the cube positive)
    const double c = 2 / (9 * dof), q = std::max(0.1, 1 - c - std::sqrt(c));
    return 1 / std::sqrt(q * q * q);
}

// A ray's passes so far.
struct RayState {
    int samples = 0, passes = 0;
    int next = 0;                           // the samples of its next pass (0: done)
    double sum = 0, var = 0;                // sums of samples x pass mean, samples^2 x its variance
    double var_spread = 0;                  // sum of (samples^2 x variance)^2 / dof (Satterthwaite)
    std::vector<double> record, entry_var;  // sums of samples x mean, samples^2 x its variance

    // The relative standard error of sum / samples: 0 for a ray that saw no light at all (in
    // all the samples of the cap).
    double Error() const { return sum == 0 ? 0 : std::sqrt(var) / std::fabs(sum); }
    double Dof() const { return var_spread > 0 ? var * var / var_spread : 0; }
    void Add(const PassResult &r, size_t k, int pass_samples, size_t width) {
        const double s2 = double(pass_samples) * pass_samples;
        for (size_t j = 0; j < width; ++j) {
            record[j] += pass_samples * r.records[width * k + j];
            entry_var[j] += s2 * r.entry_variance[width * k + j];
        }
        samples += pass_samples;
        ++passes;
        sum += pass_samples * r.mean[k];
        const double w = double(pass_samples) * pass_samples * r.variance[k];
        var += w;
        if (w > 0) var_spread += w * w / r.dof[k];
    }
    // The next pass's samples: 0 once the error's bound is at the target (after two passes at
    // least; a ray that has seen no light goes on, as its first samples may all have missed a
    // small window) or the samples at the cap; else twice the last pass's, at most what the cap
    // leaves. (Sizing the pass from the error was tried and is not kept: docs/benchmarks.md.)
    int Next(int last, int cap, double target) const {
        if (samples >= cap || (passes >= 2 && AtTarget(target))) return 0;
        return std::min(2 * last, cap - samples);
    }
    // Whether the bound of its error is at the target (a ray that saw no light is not).
    bool AtTarget(double target) const {
        return sum != 0 && !(Error() * UpperBoundFactor(Dof()) > target);
    }
};

class TargetErrorEngine : public ContribEngine {
  public:
    TargetErrorEngine(EngineMaker make, const TargetErrorOptions &o,
                      std::shared_ptr<TargetErrorReport> report)
        : make_(std::move(make)), o_(o), report_(std::move(report)) {
        // (the first pass's engine: a pair's halves for sensors, else the replicas')
        first_ = Engine(
            std::max(1, FirstPassSamples(o_.max_samples) / (o_.sensors ? 2 : kPassReplicas)));
        if (!o_.weights.empty() && static_cast<int>(o_.weights.size()) != first_->Columns())
            ErrorExit("-target_sky: " + std::to_string(o_.weights.size()) + " values for " +
                      std::to_string(first_->Columns()) + " columns");
    }

    std::string Label() const override { return first_->Label(); }
    int Columns() const override { return first_->Columns(); }
    size_t BatchRays() const override { return first_->BatchRays(); }

    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) override {
        TraceWith(rays, n, first_index, replica, records, nullptr);
    }
    // -se: each entry's variance, that of the passes' weighted mean (their replicas' spread).
    bool TraceWithVariances(const double *rays, size_t n, uint64_t first_index, double *records,
                            double *variances) override {
        TraceWith(rays, n, first_index, 0, records, variances);
        return true;
    }

  private:
    void TraceWith(const double *rays, size_t n, uint64_t first_index, int replica, double *records,
                   double *variances) {
        const size_t width = Width();
        std::vector<RayState> state(n);
        for (size_t i = 0; i < n; ++i) {
            const double *d = rays + 6 * i + 3;
            if (d[0] == 0 && d[1] == 0 && d[2] == 0) continue;  // a flush: nothing traced
            state[i].record.assign(width, 0.0);
            state[i].entry_var.assign(width, 0.0);
            state[i].next = FirstPassSamples(o_.max_samples);
        }
        // Rays at the same pass wanting as many samples go together (what each gets does not
        // depend on the others: its numbers are keyed by its index and its own pass).
        for (;;) {
            std::map<std::pair<int, int>, std::vector<size_t>> groups;  // (pass, samples): rays
            for (size_t i = 0; i < n; ++i)
                if (state[i].next > 0) groups[{state[i].passes, state[i].next}].push_back(i);
            if (groups.empty()) break;
            for (const auto &[key, members] : groups)
                RunPass(rays, first_index, replica * 128 + key.first, key.second, members, state);
        }
        std::vector<TargetErrorReport::Ray> done;
        for (size_t i = 0; i < n; ++i) {
            RayState &s = state[i];
            if (s.record.empty()) continue;
            const double samples2 = double(s.samples) * s.samples;
            for (size_t j = 0; j < width; ++j) {
                records[width * i + j] += s.record[j] / s.samples;
                if (variances) variances[width * i + j] += s.entry_var[j] / samples2;
            }
            done.push_back({first_index + i, s.samples, s.Error(), s.AtTarget(o_.target)});
        }
        if (report_) report_->Add(done);
    }

    size_t Width() const { return 3 * static_cast<size_t>(Columns()); }

    // One pass of `samples` for the rays `members` of this batch, all at pass id.
    void RunPass(const double *rays, uint64_t first_index, int id, int samples,
                 const std::vector<size_t> &members, std::vector<RayState> &state) {
        std::vector<double> subset(6 * members.size());
        std::vector<uint64_t> keys(members.size());
        for (size_t k = 0; k < members.size(); ++k) {
            std::copy(rays + 6 * members[k], rays + 6 * members[k] + 6, &subset[6 * k]);
            keys[k] = first_index + members[k];
        }
        PassResult result;
        if (!o_.sensors || !PairPass(subset, keys, id, samples, result))
            ReplicaPass(subset, keys, id, samples, result);
        for (size_t k = 0; k < members.size(); ++k) {
            RayState &s = state[members[k]];
            s.Add(result, k, samples, Width());
            s.next = s.Next(samples, o_.max_samples, o_.target);
        }
    }

    // A pass of `samples` as kPassReplicas independent replicas (id: the caller's replica and
    // the pass, which key their random numbers with the replica's number).
    void ReplicaPass(const std::vector<double> &rays, const std::vector<uint64_t> &keys, int id,
                     int samples, PassResult &out) {
        const size_t width = Width(), n = keys.size();
        ContribEngine &engine = *Engine(std::max(1, samples / kPassReplicas));
        std::vector<double> one(width * n), v(n, 0.0), v2(n, 0.0), squares(width * n, 0.0);
        out.records.assign(width * n, 0.0);
        for (int r = 0; r < kPassReplicas; ++r) {
            std::fill(one.begin(), one.end(), 0.0);
            engine.TraceKeyed(rays.data(), n, keys.data(), id * kPassReplicas + r, one.data());
            for (size_t k = 0; k < n; ++k) {
                const double value = Illuminance(&one[width * k]);
                v[k] += value, v2[k] += value * value;
                for (size_t j = 0; j < width; ++j) {
                    const double x = one[width * k + j];
                    out.records[width * k + j] += x / kPassReplicas;
                    squares[width * k + j] += x * x;
                }
            }
        }
        out.entry_variance.resize(width * n);
        for (size_t j = 0; j < width * n; ++j) {
            const double m = out.records[j];
            out.entry_variance[j] =
                std::max(0.0, (squares[j] - kPassReplicas * m * m) / (kPassReplicas - 1)) /
                kPassReplicas;
        }
        out.mean.resize(n);
        out.variance.resize(n);
        out.dof.assign(n, kPassReplicas - 1);
        for (size_t k = 0; k < n; ++k) {
            const double m = v[k] / kPassReplicas;
            out.mean[k] = m;
            out.variance[k] = std::max(0.0, (v2[k] - kPassReplicas * m * m) / (kPassReplicas - 1)) /
                              kPassReplicas;
        }
    }

    // A pass of `samples` as a pair of replicas of half as many (their grids turned alike), each
    // traced in slices; the variance of the pair's mean is the sum over slices of the squared
    // differences over 4. False where the engine has no slices.
    bool PairPass(const std::vector<double> &rays, const std::vector<uint64_t> &keys, int id,
                  int samples, PassResult &out) {
        const size_t width = Width(), n = keys.size();
        const int half = std::max(1, samples / 2);
        ContribEngine &engine = *Engine(half);
        const int slices =
            std::clamp(static_cast<int>(std::sqrt(double(half)) + 0.5), 2, kMaxSlices);
        const size_t per_ray = width * static_cast<size_t>(slices);
        const size_t chunk = std::max<size_t>(1, kSliceBytes / (2 * sizeof(double) * per_ray));
        const uint32_t pair = core::kPairedReplicas + 2u * static_cast<uint32_t>(id);
        out.records.assign(width * n, 0.0);
        out.entry_variance.assign(width * n, 0.0);
        out.mean.assign(n, 0.0);
        out.variance.assign(n, 0.0);
        out.dof.assign(n, 0.0);
        std::vector<double> a, b;
        for (size_t lo = 0; lo < n; lo += chunk) {
            const size_t m = std::min(chunk, n - lo);
            a.assign(per_ray * m, 0.0);
            b.assign(per_ray * m, 0.0);
            if (!engine.TraceSlices(&rays[6 * lo], m, &keys[lo], int(pair), slices, a.data()))
                return false;
            CHECK(engine.TraceSlices(&rays[6 * lo], m, &keys[lo], int(pair + 1), slices, b.data()));
            for (size_t k = 0; k < m; ++k) {
                double sum = 0, squares = 0, fourths = 0;
                for (int s = 0; s < slices; ++s) {
                    const double *sa = &a[per_ray * k + width * s],
                                 *sb = &b[per_ray * k + width * s];
                    const double ia = Illuminance(sa), ib = Illuminance(sb);
                    sum += ia + ib;
                    squares += (ia - ib) * (ia - ib);
                    fourths += (ia - ib) * (ia - ib) * (ia - ib) * (ia - ib);
                    double *record = &out.records[width * (lo + k)],
                           *var = &out.entry_variance[width * (lo + k)];
                    for (size_t j = 0; j < width; ++j) {
                        record[j] += 0.5 * (sa[j] + sb[j]);
                        var[j] += 0.25 * (sa[j] - sb[j]) * (sa[j] - sb[j]);
                    }
                }
                out.mean[lo + k] = 0.5 * sum;
                out.variance[lo + k] = 0.25 * squares;
                out.dof[lo + k] = fourths > 0 ? squares * squares / fourths : 0;
            }
        }
        return true;
    }

    // The record's illuminance under the reference sky (luminance of its columns, weighted).
    double Illuminance(const double *record) const {
        double sum = 0;
        for (size_t j = 0; j < static_cast<size_t>(Columns()); ++j) {
            const double *c = record + 3 * j;
            const double lum = 0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2];
            sum += (o_.weights.empty() ? 1.0 : o_.weights[j]) * lum;
        }
        return sum;
    }
    // The engine with this many divisions per replica (made once, shared by the threads).
    ContribEngine *Engine(int divisions) {
        const std::lock_guard<std::mutex> lock(mutex_);
        std::unique_ptr<ContribEngine> &e = engines_[divisions];
        if (!e) e = make_(divisions);
        return e.get();
    }

    EngineMaker make_;
    TargetErrorOptions o_;
    std::shared_ptr<TargetErrorReport> report_;
    std::mutex mutex_;
    std::map<int, std::unique_ptr<ContribEngine>> engines_;
    ContribEngine *first_ = nullptr;
};

}  // namespace

void TargetErrorReport::Add(const std::vector<Ray> &rays) {
    const std::lock_guard<std::mutex> lock(mutex_);
    rays_.insert(rays_.end(), rays.begin(), rays.end());
}

std::vector<TargetErrorReport::Ray> TargetErrorReport::Rays() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Ray> sorted = rays_;
    std::sort(sorted.begin(), sorted.end(),
              [](const Ray &a, const Ray &b) { return a.index < b.index; });
    return sorted;
}

std::string TargetErrorReport::Summary(const TargetErrorOptions &o) const {
    const std::vector<Ray> rays = Rays();
    size_t at_target = 0, at_cap = 0;
    double worst = 0;
    long long samples = 0;
    for (const Ray &r : rays) {
        if (r.at_target)
            ++at_target;
        else
            ++at_cap;
        worst = std::max(worst, r.error);
        samples += r.samples;
    }
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "-target_error %g: %zu of %zu sensors at the target, %zu at the cap (%d "
                  "samples); the worst error %.2f %%; %.0f samples a sensor on average",
                  o.target, at_target, rays.size(), at_cap, o.max_samples, 100 * worst,
                  rays.empty() ? 0.0 : double(samples) / rays.size());
    return buf;
}

std::unique_ptr<ContribEngine> WithTargetError(EngineMaker make_engine,
                                               const TargetErrorOptions &options,
                                               std::shared_ptr<TargetErrorReport> report) {
    CHECK(options.target > 0 && options.max_samples > 0);
    return std::make_unique<TargetErrorEngine>(std::move(make_engine), options, std::move(report));
}

}  // namespace dayflux
