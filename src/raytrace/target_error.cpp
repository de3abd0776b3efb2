#include "raytrace/target_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "util/errors.h"

namespace dayflux {

namespace {

constexpr int kPassReplicas = 8;  // replicas per pass: the spread that estimates its error

// The first pass's samples: a 32nd of the cap, at least 8 per replica.
int FirstPassSamples(int cap) { return std::min(cap, std::max(8 * kPassReplicas, cap / 32)); }

class TargetErrorEngine : public ContribEngine {
  public:
    TargetErrorEngine(EngineMaker make, const TargetErrorOptions &o,
                      std::shared_ptr<TargetErrorReport> report)
        : make_(std::move(make)), o_(o), report_(std::move(report)) {
        first_ = Engine(FirstPassSamples(o_.max_samples) / kPassReplicas);
        if (!o_.weights.empty() && static_cast<int>(o_.weights.size()) != first_->Columns())
            ErrorExit("-target_sky: " + std::to_string(o_.weights.size()) + " values for " +
                      std::to_string(first_->Columns()) + " columns");
    }

    std::string Label() const override { return first_->Label(); }
    int Columns() const override { return first_->Columns(); }
    size_t BatchRays() const override { return first_->BatchRays(); }

    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) override {
        const size_t width = 3 * static_cast<size_t>(Columns());
        struct State {
            int samples = 0;
            double sum = 0, var = 0;  // sums of samples x pass mean, samples^2 x its variance
            std::vector<double> record;
            bool done = false;
        };
        std::vector<State> state(n);
        std::vector<size_t> active;
        for (size_t i = 0; i < n; ++i) {
            const double *d = rays + 6 * i + 3;
            if (d[0] == 0 && d[1] == 0 && d[2] == 0) continue;  // a flush: nothing traced
            state[i].record.assign(width, 0.0);
            active.push_back(i);
        }
        for (int pass = 0, cum = 0; !active.empty(); ++pass) {
            const int samples = std::min(FirstPassSamples(o_.max_samples) << std::min(pass, 20),
                                         o_.max_samples - cum);
            cum += samples;
            ContribEngine &engine = *Engine(std::max(1, samples / kPassReplicas));
            std::vector<double> subset(6 * active.size()), one(width * active.size());
            std::vector<uint64_t> keys(active.size());
            for (size_t k = 0; k < active.size(); ++k) {
                std::copy(rays + 6 * active[k], rays + 6 * active[k] + 6, &subset[6 * k]);
                keys[k] = first_index + active[k];
            }
            std::vector<double> mean(width * active.size(), 0.0), v(active.size(), 0.0),
                v2(active.size(), 0.0);
            for (int r = 0; r < kPassReplicas; ++r) {
                std::fill(one.begin(), one.end(), 0.0);
                // random numbers of their own: the caller's replica (-se), the pass, this one
                const int id = (replica * 64 + pass) * kPassReplicas + r;
                engine.TraceKeyed(subset.data(), active.size(), keys.data(), id, one.data());
                for (size_t k = 0; k < active.size(); ++k) {
                    const double value = Illuminance(&one[width * k]);
                    v[k] += value, v2[k] += value * value;
                    for (size_t j = 0; j < width; ++j) mean[width * k + j] += one[width * k + j];
                }
            }
            std::vector<size_t> next;
            for (size_t k = 0; k < active.size(); ++k) {
                State &s = state[active[k]];
                const double m = v[k] / kPassReplicas;
                const double var =
                    std::max(0.0, (v2[k] - kPassReplicas * m * m) / (kPassReplicas - 1)) /
                    kPassReplicas;
                for (size_t j = 0; j < width; ++j)
                    s.record[j] += samples * (mean[width * k + j] / kPassReplicas);
                s.samples += samples;
                s.sum += samples * m;
                s.var += double(samples) * samples * var;
                // (a ray that has seen no light yet goes on: its first samples may all have
                // missed a small window)
                if ((s.sum != 0 && !(Error(s.sum, s.var) > o_.target)) || cum >= o_.max_samples)
                    s.done = true;
                else
                    next.push_back(active[k]);
            }
            active.swap(next);
        }
        std::vector<TargetErrorReport::Ray> done;
        for (size_t i = 0; i < n; ++i) {
            State &s = state[i];
            if (s.record.empty()) continue;
            for (size_t j = 0; j < width; ++j) records[width * i + j] += s.record[j] / s.samples;
            done.push_back({first_index + i, s.samples, Error(s.sum, s.var)});
        }
        if (report_) report_->Add(done);
    }

  private:
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
    // The relative standard error of sum / samples: 0 for a ray that saw no light at all (in all
    // the samples of the cap).
    static double Error(double sum, double var) {
        return sum == 0 ? 0 : std::sqrt(var) / std::fabs(sum);
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
        if (r.error <= o.target)
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
