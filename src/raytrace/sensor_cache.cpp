#include "raytrace/sensor_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "raytrace/backend.h"
#include "util/errors.h"

namespace dayflux {

namespace {

struct Sensor {
    double p[3], n[3];
};

Sensor SensorOf(const double *ray) {
    Sensor s{{ray[0], ray[1], ray[2]}, {ray[3], ray[4], ray[5]}};
    const double len = std::sqrt(s.n[0] * s.n[0] + s.n[1] * s.n[1] + s.n[2] * s.n[2]);
    for (double &c : s.n) c /= len > 0 ? len : 1;
    return s;
}

// The scene's extent (the largest side of its bounding box, distant sources left out), which
// -ar divides as rtrace divides its octree's cube.
double SceneSize(const FlatScene &scene) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<double>::max(), hi[k] = -lo[k];
    const auto add = [&](const double *p, double r) {
        for (int k = 0; k < 3; ++k)
            lo[k] = std::min(lo[k], p[k] - r), hi[k] = std::max(hi[k], p[k] + r);
    };
    for (const Vec3 &v : scene.vertices) add(&v[0], 0);
    for (const AnalyticShape &s : scene.shapes) {
        if (s.kind == AnalyticShape::kSource) continue;
        const double r = std::max(s.r0, s.r1);
        add(&s.p0[0], r);
        if (s.kind == AnalyticShape::kCone || s.kind == AnalyticShape::kCylinder) add(&s.p1[0], r);
    }
    double size = 0;
    for (int k = 0; k < 3; ++k) size = std::max(size, hi[k] - lo[k]);
    return size > 0 ? size : 1;
}

// A small deterministic generator per sensor (splitmix64).
struct Random {
    uint64_t state;
    double Next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return ((z ^ (z >> 31)) >> 11) * (1.0 / 9007199254740992.0);
    }
};

// Harmonic mean distance of a stratified cosine-weighted hemisphere around the sensor's normal.
double Radius(const Backend &backend, const Sensor &s, int rays, uint64_t key) {
    double u[3], v[3];
    const double *n = s.n;
    const double a[3] = {std::fabs(n[0]) < 0.6 ? 1.0 : 0.0, std::fabs(n[0]) < 0.6 ? 0.0 : 1.0, 0};
    u[0] = a[1] * n[2] - a[2] * n[1], u[1] = a[2] * n[0] - a[0] * n[2],
    u[2] = a[0] * n[1] - a[1] * n[0];
    const double lu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double &c : u) c /= lu;
    v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2],
    v[2] = n[0] * u[1] - n[1] * u[0];
    const int side = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(rays))));
    std::vector<TraceRay> batch;
    Random rng{key};
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            const double r2 = (i + rng.Next()) / side, phi = 2 * M_PI * (j + rng.Next()) / side;
            const double r = std::sqrt(r2), z = std::sqrt(std::max(0.0, 1 - r2));
            TraceRay t;
            for (int k = 0; k < 3; ++k) {
                t.org[k] = s.p[k];
                t.dir[k] = r * std::cos(phi) * u[k] + r * std::sin(phi) * v[k] + z * n[k];
            }
            t.tmax = std::numeric_limits<double>::infinity();
            batch.push_back(t);
        }
    std::vector<TraceHit> hits(batch.size());
    backend.Closest(batch.data(), hits.data(), batch.size());
    double inverse = 0;
    for (const TraceHit &h : hits)
        if (h.hit && h.t > 0) inverse += 1 / h.t;
    return inverse > 0 ? batch.size() / inverse : std::numeric_limits<double>::infinity();
}

// Ward's error of record r at sensor s, or infinity where the record does not apply (behind, or
// in front of the sensor).
double Error(const Sensor &s, const Sensor &r, double radius) {
    double d[3], dist2 = 0, dot = 0, front = 0;
    for (int k = 0; k < 3; ++k) {
        d[k] = s.p[k] - r.p[k];
        dist2 += d[k] * d[k];
        dot += s.n[k] * r.n[k];
        front += d[k] * (s.n[k] + r.n[k]) * 0.5;
    }
    if (front < -0.05 * radius) return std::numeric_limits<double>::infinity();
    return std::sqrt(dist2) / radius + std::sqrt(std::max(0.0, 1 - dot));
}

// Traces sensors `which` (ascending) into out (one record each, in that order), each with its
// own key, so that its random numbers are the ones it would draw in a whole run.
void TraceSome(ContribEngine &engine, const double *rays, const uint64_t *keys,
               const std::vector<size_t> &which, int replica, double *out) {
    std::vector<double> some(6 * which.size());
    std::vector<uint64_t> some_keys(which.size());
    for (size_t k = 0; k < which.size(); ++k) {
        std::copy(rays + 6 * which[k], rays + 6 * which[k] + 6, &some[6 * k]);
        some_keys[k] = keys[which[k]];
    }
    engine.TraceKeyed(some.data(), which.size(), some_keys.data(), replica, out);
}

}  // namespace

SensorCacheStats TraceWithSensorCache(ContribEngine &full, ContribEngine &direct,
                                      const FlatScene &scene, const Backend &caster,
                                      const double *all_rays, size_t n, const uint64_t *all_keys,
                                      int replica, const SensorCacheOptions &o,
                                      double *all_records) {
    const size_t width = 3 * static_cast<size_t>(full.Columns());
    std::fill(all_records, all_records + n * width, 0.0);
    // Zero rays are no sensors.
    std::vector<double> ray_list;
    std::vector<uint64_t> key_list;
    std::vector<size_t> where;
    for (size_t i = 0; i < n; ++i) {
        const double *r = all_rays + 6 * i;
        if (r[3] == 0 && r[4] == 0 && r[5] == 0) continue;
        ray_list.insert(ray_list.end(), r, r + 6);
        key_list.push_back(all_keys[i]);
        where.push_back(i);
    }
    const double *rays = ray_list.data();
    const uint64_t *keys = key_list.data();
    n = where.size();
    std::vector<double> record_list(n * width, 0.0);
    double *records = record_list.data();
    SensorCacheStats stats;
    stats.sensors = n;
    std::vector<Sensor> sensors(n);
    for (size_t i = 0; i < n; ++i) sensors[i] = SensorOf(rays + 6 * i);

    // 1. Radii.
    const double size = SceneSize(scene);
    const double min_radius = o.resolution > 0 ? size / o.resolution : 0;
    const double max_radius =
        o.resolution > 0 ? 64 * min_radius : std::numeric_limits<double>::infinity();
    std::vector<double> radius(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const double r =
            Radius(caster, sensors[i], o.radius_rays, o.seed * 0x632be59bd9b4e019ull + keys[i]);
        radius[i] = std::clamp(r, min_radius, max_radius);
    });

    // 2. Records, in sensor order.
    std::vector<size_t> chosen;
    for (size_t i = 0; i < n; ++i) {
        bool covered = false;
        for (size_t r : chosen)
            if (Error(sensors[i], sensors[r], radius[r]) < o.accuracy) {
                covered = true;
                break;
            }
        if (!covered) chosen.push_back(i);
    }
    stats.records = chosen.size();

    // 3. The records traced, and everyone's direct light, each sensor keeping its own random
    // numbers (a GPU takes the records, scattered over the sensors, in one dispatch).
    std::vector<double> direct_part(n * width, 0.0);
    std::vector<double> chosen_records(chosen.size() * width, 0.0);
    std::vector<size_t> all(n);
    for (size_t i = 0; i < n; ++i) all[i] = i;
    TraceSome(full, rays, keys, chosen, replica, chosen_records.data());
    TraceSome(direct, rays, keys, all, replica, direct_part.data());

    // 4. Interpolation.
    std::vector<int> record_of(n, -1);
    for (size_t k = 0; k < chosen.size(); ++k) record_of[chosen[k]] = static_cast<int>(k);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        double *out = records + i * width;
        if (record_of[i] >= 0) {
            std::copy_n(&chosen_records[record_of[i] * width], width, out);
            return;
        }
        double weights = 0;
        for (size_t k = 0; k < chosen.size(); ++k) {
            const double e = Error(sensors[i], sensors[chosen[k]], radius[chosen[k]]);
            if (!(e < o.accuracy)) continue;
            const double w = 1 / std::max(e, 1e-6);
            weights += w;
            const double *rec = &chosen_records[k * width], *dir = &direct_part[chosen[k] * width];
            for (size_t c = 0; c < width; ++c) out[c] += w * (rec[c] - dir[c]);
        }
        const double *own = &direct_part[i * width];
        for (size_t c = 0; c < width; ++c) out[c] = out[c] / weights + own[c];
    });
    for (size_t i = 0; i < n; ++i)
        std::copy_n(&record_list[i * width], width, all_records + where[i] * width);
    return stats;
}

namespace {

class SensorCachedEngine : public ContribEngine {
  public:
    SensorCachedEngine(std::unique_ptr<ContribEngine> full, std::unique_ptr<ContribEngine> direct,
                       const FlatScene &scene, const SensorCacheOptions &o, bool report)
        : full_(std::move(full)),
          direct_(std::move(direct)),
          scene_(scene),
          caster_(CreateEmbreeBackend()),
          o_(o),
          report_(report) {
        caster_->Commit(scene_);
    }
    ~SensorCachedEngine() override {
        if (report_)
            std::fprintf(stderr, "%s: sensor cache: %zu records for %zu sensors\n",
                         ProgramName().c_str(), records_.load(), sensors_.load());
    }
    std::string Label() const override { return full_->Label() + ", sensor cache"; }
    int Columns() const override { return full_->Columns(); }
    // Sensors share records only within a batch.
    size_t BatchRays() const override { return std::max<size_t>(full_->BatchRays(), 4096); }
    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) override {
        std::vector<uint64_t> keys(n);
        for (size_t i = 0; i < n; ++i) keys[i] = first_index + i;
        const SensorCacheStats s = TraceWithSensorCache(*full_, *direct_, scene_, *caster_, rays, n,
                                                        keys.data(), replica, o_, records);
        records_ += s.records, sensors_ += s.sensors;
    }

  private:
    std::unique_ptr<ContribEngine> full_, direct_;
    const FlatScene &scene_;
    std::unique_ptr<Backend> caster_;
    SensorCacheOptions o_;
    bool report_;
    std::atomic<size_t> records_{0}, sensors_{0};
};

}  // namespace

std::unique_ptr<ContribEngine> WithSensorCache(std::unique_ptr<ContribEngine> full,
                                               std::unique_ptr<ContribEngine> direct,
                                               const FlatScene &scene,
                                               const SensorCacheOptions &options, bool report) {
    return std::make_unique<SensorCachedEngine>(std::move(full), std::move(direct), scene, options,
                                                report);
}

}  // namespace dayflux
