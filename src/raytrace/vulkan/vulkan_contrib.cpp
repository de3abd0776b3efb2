#include "raytrace/vulkan/vulkan_contrib.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <mutex>
#include <thread>

#include "raytrace/analytic.h"
#include "raytrace/bvh.h"
#include "raytrace/core/tables.h"
#include "raytrace/vulkan/contrib_shader.h"
#include "raytrace/vulkan/raytracing.h"
#include "raytrace/vulkan/shaders/common.h"
#include "util/errors.h"

namespace dayflux {

namespace {

// std430's layouts of these are their C++ layouts: no padding between their members.
static_assert(sizeof(core::GpuTasks) == 56 && offsetof(core::GpuTasks, tmin) == 32);
static_assert(sizeof(core::GpuParameters) == 84 && offsetof(core::GpuParameters, lw) == 24 &&
              offsetof(core::GpuParameters, ab) == 44 && offsetof(core::GpuParameters, seed) == 80);

// Bytes of results per dispatch: within every device's maxStorageBufferRange (lavapipe: 128 MiB).
constexpr size_t kAccumBudget = size_t(64) << 20;
constexpr uint32_t kMaxTasksPerRun = 65535u * kGpuLocalSize;

// The driver's buffers set by their kBinding* names (shaders/common.h), then laid out as
// GpuDevice takes them: every binding from the first buffer one (0 without ray queries, where
// kBindingScene is our BVH; 1 with them) set exactly once.
class NamedBindings {
  public:
    void Set(int binding, const vk::GpuDevice::Binding &b) {
        CHECK(binding >= 0 && binding < core::kBindingCount && !set_[binding]);
        bindings_[binding] = b;
        set_[binding] = true;
    }
    // What every dispatch binds besides the scene: its tasks record, the run's parameters and
    // its counts (host vectors).
    void SetDispatch(std::vector<uint8_t> *tasks, std::vector<uint8_t> *parameters,
                     std::vector<uint8_t> *stats) {
        Set(core::kBindingTasks, vk::GpuDevice::In(tasks));
        Set(core::kBindingParameters, vk::GpuDevice::In(parameters));
        Set(core::kBindingStats, vk::GpuDevice::InOut(stats));
    }
    // Bindings this dispatch's shader does not read: an empty host vector each.
    void SetUnused(std::initializer_list<int> bindings, std::vector<uint8_t> *none) {
        for (int b : bindings) Set(b, vk::GpuDevice::In(none));
    }
    std::vector<vk::GpuDevice::Binding> InOrder(bool ray_queries) const {
        const int first = ray_queries ? core::kBindingScene + 1 : core::kBindingScene;
        CHECK(!ray_queries || !set_[core::kBindingScene]);  // the acceleration structure's
        std::vector<vk::GpuDevice::Binding> in_order;
        for (int b = first; b < core::kBindingCount; ++b) {
            CHECK(set_[b]);
            in_order.push_back(bindings_[b]);
        }
        return in_order;
    }

  private:
    std::array<vk::GpuDevice::Binding, core::kBindingCount> bindings_{};
    std::array<bool, core::kBindingCount> set_{};
};

template <class T>
std::vector<uint8_t> Bytes(const std::vector<T> &v) {
    std::vector<uint8_t> b(std::max<size_t>(v.size() * sizeof(T), 16), 0);
    if (!v.empty()) std::memcpy(b.data(), v.data(), v.size() * sizeof(T));
    return b;
}

// The triangles as a device traverses them: positions (float, recentred) and indices; our BVH
// over them and the analytic shapes' boxes where a device has no ray queries.
struct Geometry {
    std::vector<float> positions, boxes;
    std::vector<uint32_t> indices;
    std::vector<uint8_t> bvh_nodes, bvh_prims;  // built on first need

    Geometry(const FlatScene &scene, const PackedScene &packed) {
        positions.reserve(scene.vertices.size() * 3);
        for (const Vec3 &v : scene.vertices)
            for (int k = 0; k < 3; ++k)
                positions.push_back(static_cast<float>(v[k] - packed.centre[k]));
        indices.reserve(scene.triangles.size() * 3);
        for (const auto &t : scene.triangles) indices.insert(indices.end(), t.begin(), t.end());
        for (int i : packed.flat_shape) {
            double lo[3], hi[3];
            ShapeBounds(scene.shapes[i], packed.centre, lo, hi);
            for (double x : lo) boxes.push_back(static_cast<float>(x));
            for (double x : hi) boxes.push_back(static_cast<float>(x));
        }
    }

    // Entries i >= 0 are triangles, -(i + 1) analytic shapes.
    void BuildBvh() {
        if (!bvh_nodes.empty()) return;
        std::vector<float> bounds;
        bounds.reserve((indices.size() / 3 + boxes.size() / 6) * 6);
        for (size_t t = 0; t + 2 < indices.size(); t += 3) {
            float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
            for (size_t c = 0; c < 3; ++c)
                for (int k = 0; k < 3; ++k) {
                    const float x = positions[3 * static_cast<size_t>(indices[t + c]) + k];
                    lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
                }
            bounds.insert(bounds.end(), lo, lo + 3);
            bounds.insert(bounds.end(), hi, hi + 3);
        }
        bounds.insert(bounds.end(), boxes.begin(), boxes.end());
        const FlatBvh bvh = dayflux::BuildBvh(bounds);
        const int32_t ntri = static_cast<int32_t>(indices.size() / 3);
        bvh_nodes = Bytes(PackBvh(bvh));
        // The leaves' entries in their order: a triangle's corner and its edges from it (in
        // float, as the shader would take them: the same bits), or a shape.
        std::vector<core::PackedBvhEntry> entries(bvh.prims.size());
        for (size_t i = 0; i < entries.size(); ++i) {
            const int32_t p = bvh.prims[i];
            core::PackedBvhEntry &e = entries[i];
            e.index = p >= ntri ? -(p - ntri + 1) : p;
            if (e.index < 0) continue;
            e.corner = Corner(3 * size_t(p));
            e.edge1 = Corner(3 * size_t(p) + 1) - e.corner;
            e.edge2 = Corner(3 * size_t(p) + 2) - e.corner;
        }
        bvh_prims = Bytes(entries);
    }
    core::vec3 Corner(size_t k) const {
        const float *v = &positions[3 * size_t(indices[k])];
        return core::vec3(v[0], v[1], v[2]);
    }
};

// One device's share: the device, its compiled shader (ray queries or our BVH) and its copy of
// the scene's tables (GpuDevice::Resident handles; bvh_nodes and bvh_prims only without ray
// queries).
struct DeviceState {
    std::unique_ptr<vk::GpuDevice> device;
    std::vector<uint32_t> spirv;
    std::vector<uint32_t> sum_spirv;  // CompileSliceSumShader's (empty: plain float accumulators)
    int positions = -1, indices = -1, triangles = -1, surfaces = -1, sources = -1, shapes = -1;
    int bvh_nodes = -1, bvh_prims = -1, klems = -1, relays = -1, tracked = -1, receivers = -1;
    ShaderTarget target;      // what its SPIR-V is compiled for (the stack's place: GpuScratch)
    uint32_t item_bytes = 0;  // the shader's stack item (std430), for its scratch
    uint32_t path_start_bytes = 0;  // the paths engine's PathStart (std430)
    uint32_t walker_bytes = 0;      // and its Walker
    uint64_t dropped = 0;           // stack items lost in its last Trace
    uint32_t reports = 0;           // the core's kReport* flags, likewise
    // For benchmarks: nearest-hit queries traced, the device's seconds per stage (trace, slice
    // sums), and the rays logged (EngineOptions::gpu_ray_log), since the engine was made.
    uint64_t rays_traced = 0;
    std::vector<double> stage_seconds;
    std::vector<core::uvec4> ray_log;
    std::vector<uint32_t> replay_spirv;  // compiled when first asked for
};

using G = vk::GpuDevice;

// The bindings of the scene's tables, as uploaded (Upload), for every kernel of a device.
NamedBindings SceneBindings(const DeviceState &dev, std::vector<uint8_t> *none) {
    NamedBindings named;
    named.Set(core::kBindingPositions, G::OnDevice(dev.positions));
    named.Set(core::kBindingIndices, G::OnDevice(dev.indices));
    named.Set(core::kBindingTriangles, G::OnDevice(dev.triangles));
    named.Set(core::kBindingSurfaces, G::OnDevice(dev.surfaces));
    named.Set(core::kBindingSources, G::OnDevice(dev.sources));
    named.Set(core::kBindingShapes, G::OnDevice(dev.shapes));
    if (!dev.device->RayQueries()) {  // our BVH in place of the acceleration structure
        named.Set(core::kBindingScene, G::OnDevice(dev.bvh_nodes));
        named.Set(core::kBindingBvhPrims, G::OnDevice(dev.bvh_prims));
    } else {
        named.Set(core::kBindingBvhPrims, G::In(none));  // unused
    }
    named.Set(core::kBindingKlems, G::OnDevice(dev.klems));
    named.Set(core::kBindingRelays, G::OnDevice(dev.relays));
    named.Set(core::kBindingTracked, G::OnDevice(dev.tracked));
    named.Set(core::kBindingReceivers, G::OnDevice(dev.receivers));
    return named;
}

// The device's copy of the scene; false, with why, when its buffers cannot hold it.
bool Upload(const PackedScene &packed, const std::vector<core::ivec4> &tracked, Geometry &geometry,
            DeviceState &dev, std::string *why) {
    vk::GpuDevice &device = *dev.device;
    const uint64_t limit = device.MaxBufferBytes();
    if (geometry.positions.size() * sizeof(float) > limit ||
        packed.triangles.size() * sizeof(core::PackedTriangle) > limit ||
        geometry.indices.size() * sizeof(uint32_t) > limit) {
        *why = "the scene is too large for " + device.Name() + "'s storage buffers";
        return false;
    }
    if (device.RayQueries()) {
        device.BuildScene(geometry.positions, geometry.indices, geometry.boxes);
    } else {
        geometry.BuildBvh();
        if (std::max(geometry.bvh_nodes.size(), geometry.bvh_prims.size()) > limit) {
            *why = "the scene's BVH is too large for " + device.Name() + "'s storage buffers";
            return false;
        }
        dev.bvh_nodes = device.Resident(geometry.bvh_nodes);
        dev.bvh_prims = device.Resident(geometry.bvh_prims);
    }
    dev.positions = device.Resident(Bytes(geometry.positions));
    dev.indices = device.Resident(Bytes(geometry.indices));
    dev.triangles = device.Resident(Bytes(packed.triangles));
    dev.surfaces = device.Resident(Bytes(packed.surfaces));
    dev.sources = device.Resident(Bytes(packed.sources));
    dev.shapes = device.Resident(Bytes(packed.shapes));
    dev.klems = device.Resident(Bytes(packed.klems));
    dev.relays = device.Resident(Bytes(packed.relays));
    dev.tracked = device.Resident(Bytes(tracked));
    dev.receivers = device.Resident(Bytes(packed.receivers));
    return true;
}

// For the paths engine's -V+ runs (rtrace-gpu's and rtrace_dc-gpu's too): 2^e at least the
// radiance of every tracked modifier's surfaces and sources (its contributions are coefficients
// times that), e >= 0; -1 where a pattern or a mixfunc makes it unknown, or where the radiances
// spread over more than 2^16 (the dimmest's adds would be rounded to the brightest's units).
int RadianceExponent(const PackedScene &packed) {
    double most = 1, least = HUGE_VAL;
    const auto take = [&](const core::vec4 &colour) {
        for (int c = 0; c < 3; ++c) {
            const double x = std::fabs(double(colour[c]));
            most = std::max(most, x);
            if (x > 0) least = std::min(least, x);
        }
    };
    for (const core::PackedSurface &m : packed.surfaces) {
        // (antimatter keeps its counters in `pattern`, and contributes nothing of its own)
        if (m.tracked < 0 || m.kind == core::kMatAntimatter) continue;
        if (m.pattern >= 0 || m.kind == core::kMatMix) return -1;
        take(m.color);
    }
    for (const core::PackedSource &s : packed.sources) {
        if (s.tracked < 0) continue;
        if (s.pattern >= 0) return -1;
        take(s.colour);
    }
    if (least < HUGE_VAL && most > 65536 * least) return -1;
    int e;
    std::frexp(most, &e);
    return most == std::ldexp(0.5, e) ? e - 1 : e;
}

vk::Traversal DeviceTraversal(GpuTraversal t) {
    return t == GpuTraversal::kRayQuery ? vk::Traversal::kRayQuery
           : t == GpuTraversal::kBvh    ? vk::Traversal::kBvh
                                        : vk::Traversal::kAuto;
}

struct PathsPlan;

class VulkanContribEngine : public ContribEngine {
  public:
    VulkanContribEngine(const PackedScene &packed, const ContribOptions &options,
                        const EngineOptions &engine, ContribShader shader,
                        std::vector<DeviceState> devices)
        : devices_(std::move(devices)),
          o_(options),
          accumulators_(engine.accumulators),
          tasks_per_dispatch_(engine.gpu_tasks_per_dispatch),
          scratch_bytes_(engine.gpu_scratch_bytes),
          paths_(engine.gpu_engine == GpuEngine::kPaths),
          waves_(engine.gpu_waves),
          path_units_(std::ldexp(
              1.0, core::kPathFixedBits - (options.contributions ? RadianceExponent(packed) : 0))),
          ray_log_capacity_(engine.gpu_ray_log),
          float64_(engine.NeedsFloat64()),
          shader_(std::move(shader)),
          columns_(packed.columns),
          parameters_(Bytes(std::vector<core::GpuParameters>{
              MakeParameters<core::GpuParameters>(packed, options)})),
          extent_(packed.extent),
          max_rows_(std::max(1, static_cast<int>(std::sqrt(double(o_.ambient_divisions)) + 1.5))),
          nsources_(packed.sources.size()) {
        std::copy(packed.centre, packed.centre + 3, centre_);
        for (const DeviceState &d : devices_)
            names_ += (names_.empty() ? "" : " + ") + d.device->Name();
    }

    std::string Label() const override {
        return std::string(paths_ ? "vulkan paths: " : "vulkan: ") + names_;
    }
    int Columns() const override { return columns_; }
    // Many rays per dispatch, within a bound on the records' memory.
    size_t BatchRays() const override {
        return std::clamp<size_t>((size_t(64) << 20) / (24 * static_cast<size_t>(columns_)), 1,
                                  4096);
    }

    // Several devices split the rays between them, each taking a contiguous share on a thread
    // of its own: rays' random numbers are keyed by their index, so the records do not depend on
    // how many devices there are. One call at a time: the devices are not shared.
    void Trace(const double *rays, size_t n, uint64_t first_index, int replica,
               double *records) override {
        TraceAll(rays, n, first_index, nullptr, replica, records);
    }
    // The rays' keys as offsets from the first in the rays' buffer (shaders/contrib.comp), where
    // a float holds them exactly.
    void TraceKeyed(const double *rays, size_t n, const uint64_t *keys, int replica,
                    double *records) override {
        if (n > 0 && keys[n - 1] - keys[0] < kMaxKeySpan)
            TraceAll(rays, n, keys[0], keys, replica, records);
        else
            ContribEngine::TraceKeyed(rays, n, keys, replica, records);
    }
    bool TraceSlices(const double *rays, size_t n, const uint64_t *keys, int replica, int slices,
                     double *slice_records) override {
        if (n > 0 && keys[n - 1] - keys[0] >= kMaxKeySpan) return false;
        if (n > 0) TraceAll(rays, n, keys[0], keys, replica, slice_records, slices);
        return true;
    }

  private:
    static constexpr uint64_t kMaxKeySpan = uint64_t(1) << 24;

    // keys: each ray's (ascending, within kMaxKeySpan of first_index, its first), or null for
    // first_index + i. slices_apart: 0, a record a ray (its slices as the engine chooses); else
    // that many slices a ray, a record each (TraceSlices).
    void TraceAll(const double *rays, size_t n, uint64_t first_index, const uint64_t *keys,
                  int replica, double *records, int slices_apart = 0) {
        if (n == 0) return;
        std::lock_guard<std::mutex> lock(mutex_);
        const size_t nd = devices_.size(), record = 3 * static_cast<size_t>(columns_);
        std::vector<std::thread> threads;
        for (size_t k = 0; k < nd; ++k) {
            const size_t lo = n * k / nd, hi = n * (k + 1) / nd;
            if (hi == lo) continue;
            const auto run = [&, k, lo, hi] {
                TraceOn(devices_[k], rays + 6 * lo, hi - lo, keys ? keys[lo] : first_index + lo,
                        keys ? keys + lo : nullptr, replica,
                        records + lo * record * size_t(std::max(1, slices_apart)), slices_apart);
            };
            if (nd == 1)
                run();
            else
                threads.emplace_back(run);
        }
        for (std::thread &t : threads) t.join();
        uint64_t lost = 0;
        uint32_t reports = 0;
        for (DeviceState &dev : devices_) {
            lost += dev.dropped, reports |= dev.reports;
            dev.dropped = 0, dev.reports = 0;
        }
        WarnCoreReports(reports, lost);
        CHECK((reports & core::kReportWaveMissed) == 0);  // (every stopped walker was queued)
        if (reports & core::kReportFixedSum)
            throw UserError(
                "a sum passed the GPU paths engine's fixed point (32768 times its sources' "
                "radiance: a surface that reflects more than it receives?), so its values would "
                "be wrong; -gpu_engine tasks holds any float");
    }

    uint64_t RaysTraced() const override {
        uint64_t n = 0;
        for (const DeviceState &d : devices_) n += d.rays_traced;
        return n;
    }
    std::vector<double> StageSeconds() const override {
        std::vector<double> sum;
        for (const DeviceState &d : devices_) {
            sum.resize(std::max(sum.size(), d.stage_seconds.size()));
            for (size_t k = 0; k < d.stage_seconds.size(); ++k) sum[k] += d.stage_seconds[k];
        }
        return sum;
    }
    ReplayResult ReplayLoggedRays(int passes) override;

    size_t AccumBytes() const {
        return accumulators_ == GpuAccum::kFloat ? sizeof(float) : 2 * sizeof(float);
    }
    core::GpuTasks Tasks(size_t n, int slices, uint64_t first_index, int replica) const;
    void TraceOn(DeviceState &dev, const double *rays, size_t n, uint64_t first_index,
                 const uint64_t *keys, int replica, double *records, int slices_apart) const;
    PathsPlan PlanPaths(const DeviceState &dev, int slices, int slices_apart) const;
    void TracePathsOn(DeviceState &dev, std::vector<uint8_t> &ray_bytes, size_t n, int slices,
                      uint64_t first_index, int replica, double *records, int slices_apart) const;
    uint64_t LogRoom(const DeviceState &dev) const;
    // The device memory a dispatch may take (EngineOptions::gpu_scratch_bytes), else `cpu`'s
    // share on a CPU device, else the device's budget.
    uint64_t Budget(const DeviceState &dev, uint64_t cpu) const {
        if (scratch_bytes_ > 0) return scratch_bytes_;
        return dev.device->IsCpu() ? cpu : dev.device->ScratchBudget();
    }
    static void TakeStats(DeviceState &dev, const std::vector<uint8_t> &stats,
                          const std::vector<uint8_t> &log_bytes,
                          const std::vector<int> *bucket_of_stage = nullptr);

    std::vector<DeviceState> devices_;
    std::string names_;
    ContribOptions o_;
    GpuAccum accumulators_;
    int tasks_per_dispatch_;     // EngineOptions::gpu_tasks_per_dispatch
    uint64_t scratch_bytes_;     // EngineOptions::gpu_scratch_bytes
    bool paths_;                 // EngineOptions::gpu_engine: the paths engine
    int waves_;                  // EngineOptions::gpu_waves
    double path_units_;          // its fixed point's units to 1 (GpuTasks::path_scale)
    uint64_t ray_log_capacity_;  // EngineOptions::gpu_ray_log
    bool float64_;               // the run asked for doubles (EngineOptions::NeedsFloat64)
    ContribShader shader_;
    int columns_;
    std::vector<uint8_t> parameters_;  // the core's (kBindingParameters)
    double centre_[3], extent_;
    int max_rows_;     // divisions along one side of the first hemisphere (slices are rows)
    size_t nsources_;  // the light sources (slices share them out too)
    std::mutex mutex_;
};

core::GpuTasks VulkanContribEngine::Tasks(size_t n, int slices, uint64_t first_index,
                                          int replica) const {
    core::GpuTasks t{};
    t.rays = static_cast<int>(n);
    t.slices = slices;
    t.first_ray = static_cast<int>(first_index);
    t.replica = replica;
    t.ncols = columns_;
    t.tmin = static_cast<float>(std::max(1e-6 * extent_, 1e-9));
    return t;
}

void VulkanContribEngine::TraceOn(DeviceState &dev, const double *rays, size_t n,
                                  uint64_t first_index, const uint64_t *keys, int replica,
                                  double *records, int slices_apart) const {
    std::vector<core::vec4> in(2 * n);
    for (size_t i = 0; i < n; ++i) {
        const double *r = rays + 6 * i;
        const bool zero = r[3] == 0 && r[4] == 0 && r[5] == 0;
        const uint64_t offset = keys ? keys[i] - first_index : i;
        CHECK(offset < kMaxKeySpan);
        in[2 * i] = core::vec4(r[0] - centre_[0], r[1] - centre_[1], r[2] - centre_[2], 0);
        in[2 * i + 1] = core::vec4(r[3], r[4], r[5], zero ? -1.f : float(offset));
    }
    // -I rays split their first hemisphere's rows and the light sources between several tasks,
    // enough to keep the device busy; other rays are one task each. The paths engine's tasks
    // need no record of their own, so on a GPU it makes more, and splits thousands of sources
    // (C_ds's suns) beyond the rows, 16 a task at least.
    int slices = 1;
    if (slices_apart > 0) {
        slices = slices_apart;
    } else if (o_.irradiance) {
        const size_t want_tasks = paths_ && !dev.device->IsCpu() ? 1 << 18 : 1 << 16;
        const size_t most =
            paths_ ? std::max<size_t>(max_rows_, (nsources_ + 15) / 16) : size_t(max_rows_);
        slices = static_cast<int>(std::clamp<size_t>((want_tasks + n - 1) / n, 1, most));
    }
    std::vector<uint8_t> ray_bytes = Bytes(in);
    if (paths_) {
        TracePathsOn(dev, ray_bytes, n, slices, first_index, replica, records, slices_apart);
        return;
    }
    const size_t record = 3 * static_cast<size_t>(columns_);
    const size_t total = n * static_cast<size_t>(slices);
    // Each task's scratch: its stack and its rows (shaders/common.h), within the device's budget.
    const uint64_t stack_bytes = uint64_t(kGpuStackSize + 1) * dev.item_bytes;
    const uint64_t rows_bytes = 16 * uint64_t(2 * max_rows_ + kGpuDeepLevels * 2 * kGpuDeepN);
    const uint64_t scratch_tasks =
        !dev.target.scratch ? uint64_t(kMaxTasksPerRun)
                            : std::min({Budget(dev, dev.device->ScratchBudget()) /
                                            (stack_bytes + rows_bytes),
                                        dev.device->MaxBufferBytes() / stack_bytes,
                                        dev.device->MaxBufferBytes() / rows_bytes});
    // The accumulators live in device memory (a whole record a task: 5185 x 3 for C_ds), as
    // much of it as the scratch may take, so that a run holds thousands of tasks.
    const uint64_t accum_budget =
        std::min(Budget(dev, 2 * kAccumBudget) / 2, dev.device->MaxBufferBytes());
    size_t per_run = std::clamp<size_t>(
        std::min<uint64_t>(accum_budget / (record * AccumBytes()), scratch_tasks), 1,
        kMaxTasksPerRun);
    if (tasks_per_dispatch_ > 0) per_run = std::min(per_run, size_t(tasks_per_dispatch_));
    // A dispatch holding its rays' slices whole sums them on the device (a second stage), so
    // that one record a ray comes back, not one a slice: C_ds's records (5185 x 3 doubles, 20
    // slices a sensor) were 35 GB copied back and added on the host for the large office, most
    // of its run on a GPU (docs/benchmarks.md). With double accumulators, the same sums in the
    // same order, so the same records where they start at nought (every caller's); with pairs,
    // the same to about 1e-16 (the device's TwoSum against the host's double sums), and the same
    // bytes on the same device, whose memory decides which it does.
    const bool sum_slices =
        slices > 1 && slices_apart == 0 && !dev.sum_spirv.empty() && per_run >= size_t(slices);
    if (sum_slices) per_run -= per_run % slices;
    std::vector<uint8_t> accum, parameter_bytes = parameters_;
    for (size_t offset = 0; offset < total; offset += per_run) {
        const size_t count = std::min(per_run, total - offset);
        core::GpuTasks tasks = Tasks(n, slices, first_index, replica);
        tasks.maxn = max_rows_;
        tasks.task_offset = static_cast<int>(offset);
        tasks.count = static_cast<int>(count);
        std::vector<uint8_t> task_bytes(sizeof tasks);
        // zeroed on the device; with sum_slices, the rays' sums
        accum.resize((sum_slices ? count / slices : count) * record * AccumBytes());
        std::vector<uint8_t> stats(20, 0), none;
        tasks.log_capacity = static_cast<int>(LogRoom(dev));
        std::memcpy(task_bytes.data(), &tasks, sizeof tasks);
        std::vector<uint8_t> log_bytes(size_t(tasks.log_capacity) * 2 * sizeof(core::uvec4));
        NamedBindings named = SceneBindings(dev, &none);
        named.Set(core::kBindingRays, G::In(&ray_bytes));
        named.Set(core::kBindingAccum, sum_slices ? G::ZeroedScratch(count * record * AccumBytes())
                                                  : G::Accumulator(&accum));
        named.SetDispatch(&task_bytes, &parameter_bytes, &stats);
        named.Set(core::kBindingScratchItems,
                  dev.target.scratch ? G::Scratch(count * stack_bytes) : G::In(&none));
        named.Set(core::kBindingScratchRows,
                  dev.target.scratch ? G::Scratch(count * rows_bytes) : G::In(&none));
        named.Set(core::kBindingSliceSums, sum_slices ? G::Accumulator(&accum) : G::In(&none));
        named.Set(core::kBindingRayLog,
                  log_bytes.empty() ? G::In(&none) : G::Accumulator(&log_bytes));
        named.SetUnused({core::kBindingPathStarts, core::kBindingPathCount, core::kBindingWalkers,
                         core::kBindingWaveQueue},
                        &none);
        const std::vector<G::Binding> buffers = named.InOrder(dev.device->RayQueries());
        std::vector<G::Stage> stages = {{&dev.spirv, static_cast<uint32_t>(count), kGpuLocalSize}};
        if (sum_slices)
            stages.push_back({&dev.sum_spirv, static_cast<uint32_t>(count / slices * record),
                              kSliceSumLocalSize});
        dev.device->RunStages(stages, buffers);
        TakeStats(dev, stats, log_bytes);
        // entry(i): entry i of the records read back, in double
        const auto add = [&](const auto &entry) {
            const size_t step = sum_slices ? slices : 1;  // tasks a record read back stands for
            for (size_t t = 0; t < count; t += step) {
                double *dst =
                    records + (slices_apart > 0 ? offset + t : (offset + t) / slices) * record;
                const size_t src = t / step * record;
                for (size_t j = 0; j < record; ++j) dst[j] += entry(src + j);
            }
        };
        const auto *floats = reinterpret_cast<const float *>(accum.data());
        if (accumulators_ == GpuAccum::kPair)
            add([floats](size_t i) { return double(floats[2 * i]) + double(floats[2 * i + 1]); });
        else if (accumulators_ == GpuAccum::kFloat)
            add([floats](size_t i) { return double(floats[i]); });
        else
            add([&accum](size_t i) { return reinterpret_cast<const double *>(accum.data())[i]; });
    }
}

// The rays a dispatch may log: what the log has room for (the whole log is one buffer for the
// replay, so within a buffer's range).
uint64_t VulkanContribEngine::LogRoom(const DeviceState &dev) const {
    const uint64_t log_capacity = std::min<uint64_t>(
        ray_log_capacity_, dev.device->MaxBufferBytes() / (2 * sizeof(core::uvec4)));
    const uint64_t room = log_capacity - std::min<uint64_t>(log_capacity, dev.ray_log.size() / 2);
    return std::min<uint64_t>(room, INT32_MAX);
}

// A dispatch's counts (shaders/common.h's kBindingStats), stage times and logged rays, added to
// the device's: stage k's time to entry k, or to entry (*bucket_of_stage)[k].
void VulkanContribEngine::TakeStats(DeviceState &dev, const std::vector<uint8_t> &stats,
                                    const std::vector<uint8_t> &log_bytes,
                                    const std::vector<int> *bucket_of_stage) {
    uint32_t stat[5];
    std::memcpy(stat, stats.data(), sizeof stat);
    dev.dropped += stat[0];
    dev.reports |= stat[1];
    dev.rays_traced += stat[2] + (uint64_t{stat[4]} << 32);
    const std::vector<double> &seconds = dev.device->LastStageSeconds();
    for (size_t k = 0; k < seconds.size(); ++k) {
        const size_t at = bucket_of_stage ? size_t((*bucket_of_stage)[k]) : k;
        if (dev.stage_seconds.size() <= at) dev.stage_seconds.resize(at + 1);
        dev.stage_seconds[at] += seconds[k];
    }
    const size_t logged = std::min<size_t>(stat[3], log_bytes.size() / (2 * sizeof(core::uvec4)));
    const auto *log = reinterpret_cast<const core::uvec4 *>(log_bytes.data());
    dev.ray_log.insert(dev.ray_log.end(), log, log + 2 * logged);
}

// How the paths engine shares a call out between dispatches: the tasks each takes, whose adds
// go to one record, its cells' room and its walkers.
struct PathsPlan {
    int slices = 1;
    uint64_t ray_cells = 0;   // a ray's cells, over all its slices (-asub: each cell's steps)
    uint64_t task_cells = 0;  // a task's (its rows')
    uint64_t stack_bytes = 0, rows_bytes = 0, slot_bytes = 0;  // an invocation's scratch
    uint64_t per_run = 0;                                      // tasks a dispatch
    size_t per_record = 1;                                     // tasks adding to one record
    uint64_t walker_cap = 0;  // phase 1's invocations at most, whole groups
    // The cells `count` tasks may start: they span at most one ray more than they fill, and a
    // task starts only its rows' cells.
    uint64_t Cells(uint64_t count) const {
        return std::min(((count + slices - 1) / slices + 1) * ray_cells, count * task_cells);
    }
};

PathsPlan VulkanContribEngine::PlanPaths(const DeviceState &dev, int slices,
                                         int slices_apart) const {
    PathsPlan p;
    p.slices = slices;
    const uint64_t asub = static_cast<uint64_t>(std::max(1, o_.ambient_subsamples));
    if (o_.irradiance && o_.ambient_bounces > 0)  // (else no hemisphere: no cells)
        p.ray_cells = uint64_t(max_rows_) * uint64_t(max_rows_) * asub * asub;
    p.task_cells = p.ray_cells / max_rows_ * ((uint64_t(max_rows_) + slices - 1) / slices);
    p.stack_bytes = uint64_t(kGpuStackSize + 1) * dev.item_bytes;
    p.rows_bytes = 16 * uint64_t(2 * max_rows_ + kGpuDeepLevels * 2 * kGpuDeepN);
    p.slot_bytes = dev.target.scratch ? p.stack_bytes + p.rows_bytes : 0;
    // Device memory: an eighth of the budget for the records, a quarter for the cells, half for
    // the invocations' stacks and rows, as many of them as can walk at once (lavapipe's: the
    // machine's memory, so a fixed share).
    const uint64_t budget = Budget(dev, 4 * kAccumBudget);
    const uint64_t buffer = dev.device->MaxBufferBytes();
    const uint64_t record = 3 * static_cast<uint64_t>(columns_);
    const uint64_t records_room = std::min(budget / 8, buffer) / (record * sizeof(uint64_t));
    const uint64_t slots_room =
        p.slot_bytes > 0 ? std::min(budget / 2, buffer) / p.slot_bytes : uint64_t(1) << 16;
    // The tasks whose cells the buffer holds: whole rays, or (where not two fit) single tasks.
    const uint64_t starts_room = std::min(budget / 4, buffer) / dev.path_start_bytes;
    const uint64_t rays_room = p.ray_cells > 0 ? starts_room / p.ray_cells : 0;
    const uint64_t cells_room =
        p.ray_cells == 0
            ? uint64_t(kMaxTasksPerRun)
            : std::max(rays_room > 1 ? (rays_room - 1) * slices : 0, starts_room / p.task_cells);
    p.per_run =
        std::min<uint64_t>({records_room * slices, slots_room, kMaxTasksPerRun, cells_room});
    if (tasks_per_dispatch_ > 0) p.per_run = std::min<uint64_t>(p.per_run, tasks_per_dispatch_);
    // A ray's slices add to one record where a dispatch holds them whole (else a record a task,
    // the host adding a ray's up: exact integers either way).
    p.per_record = slices_apart == 0 && p.per_run >= uint64_t(slices) ? slices : 1;
    p.per_run = std::min(p.per_run - p.per_run % p.per_record, records_room * p.per_record);
    p.walker_cap = std::min<uint64_t>(slots_room, kMaxTasksPerRun) / kGpuLocalSize * kGpuLocalSize;
    if (p.per_run == 0 || p.walker_cap == 0)
        ErrorExit("the GPU paths engine cannot hold one sensor's record and cells on " +
                  dev.device->Name() + "; -gpu_engine tasks needs less");
    return p;
}

// The paths engine (EngineOptions::gpu_engine): each dispatch runs the shader twice in one
// submission, phase 0 an invocation a task (its sources, and its cells' rays and random states
// kept on the device), phase 1 over those cells' paths; the records, in fixed point, come back
// one a ray (or a slice, with slices_apart), summed as integers, then added to records as doubles.
void VulkanContribEngine::TracePathsOn(DeviceState &dev, std::vector<uint8_t> &ray_bytes, size_t n,
                                       int slices, uint64_t first_index, int replica,
                                       double *records, int slices_apart) const {
    const PathsPlan plan = PlanPaths(dev, slices, slices_apart);
    const size_t record = 3 * static_cast<size_t>(columns_), per_record = plan.per_record;
    const size_t total = n * static_cast<size_t>(slices);
    std::vector<uint8_t> parameter_bytes = parameters_, accum, none;
    std::vector<int64_t> sums((slices_apart > 0 ? total : n) * record, 0);
    for (size_t offset = 0; offset < total; offset += plan.per_run) {
        const size_t count = std::min<size_t>(plan.per_run, total - offset);
        const uint64_t cells = plan.Cells(count);
        // (the walkers' number is the shader's stride: whole groups, all along x)
        const uint64_t walkers =
            (std::min(cells, plan.walker_cap) + kGpuLocalSize - 1) / kGpuLocalSize * kGpuLocalSize;
        CHECK(walkers <= plan.walker_cap && walkers <= kMaxTasksPerRun);
        core::GpuTasks tasks = Tasks(n, slices, first_index, replica);
        tasks.maxn = max_rows_;
        tasks.task_offset = static_cast<int>(offset);
        tasks.count = static_cast<int>(count);
        tasks.path_capacity = static_cast<int>(cells);
        tasks.tasks_per_record = static_cast<int>(per_record);
        tasks.path_scale = static_cast<float>(path_units_);
        tasks.waves = waves_;
        tasks.log_capacity = static_cast<int>(LogRoom(dev));
        std::vector<uint8_t> task_bytes(sizeof tasks), stats(20, 0);
        std::memcpy(task_bytes.data(), &tasks, sizeof tasks);
        std::vector<uint8_t> log_bytes(size_t(tasks.log_capacity) * 2 * sizeof(core::uvec4));
        accum.resize(count / per_record * record * sizeof(uint64_t));  // zeroed on the device
        const uint64_t slots = std::max<uint64_t>(count, walkers);
        NamedBindings named = SceneBindings(dev, &none);
        named.Set(core::kBindingRays, G::In(&ray_bytes));
        named.Set(core::kBindingAccum, G::Accumulator(&accum));
        named.SetDispatch(&task_bytes, &parameter_bytes, &stats);
        named.Set(core::kBindingScratchItems,
                  plan.slot_bytes > 0 ? G::Scratch(slots * plan.stack_bytes) : G::In(&none));
        named.Set(core::kBindingScratchRows,
                  plan.slot_bytes > 0 ? G::Scratch(slots * plan.rows_bytes) : G::In(&none));
        named.SetUnused({core::kBindingSliceSums}, &none);
        named.Set(core::kBindingRayLog,
                  log_bytes.empty() ? G::In(&none) : G::Accumulator(&log_bytes));
        named.Set(core::kBindingPathStarts,
                  cells > 0 ? G::Scratch(cells * dev.path_start_bytes) : G::In(&none));
        named.Set(core::kBindingPathCount, G::ZeroedScratch(sizeof(uint32_t)));
        named.Set(core::kBindingWalkers,
                  walkers > 0 ? G::ZeroedScratch(walkers * dev.walker_bytes) : G::In(&none));
        named.Set(core::kBindingWaveQueue, walkers > 0 && waves_ > 0
                                               ? G::ZeroedScratch((waves_ + 2 * walkers) * 4)
                                               : G::In(&none));
        // The cells (phase 0); wave k, its walkers' next rays (2 + 2k) and their hits (3 + 2k);
        // the walk to the end (1). Their times summed: cells, paths, waves' rays, waves' hits.
        const uint32_t w = static_cast<uint32_t>(walkers);
        std::vector<G::Stage> stages = {
            {&dev.spirv, static_cast<uint32_t>(count), kGpuLocalSize, 0}};
        for (uint32_t k = 0; k < uint32_t(waves_); ++k)
            stages.insert(stages.end(), {{&dev.spirv, w, kGpuLocalSize, 2 + 2 * k},
                                         {&dev.spirv, w, kGpuLocalSize, 3 + 2 * k}});
        stages.push_back({&dev.spirv, w, kGpuLocalSize, 1});
        dev.device->RunStages(stages, named.InOrder(dev.device->RayQueries()));
        std::vector<int> phase_of;  // (of the stages that ran: those with invocations)
        for (const G::Stage &stage : stages)
            if (stage.invocations > 0)
                phase_of.push_back(stage.phase < 2 ? int(stage.phase)
                                                   : 2 + int(stage.phase % 2 == 1));
        TakeStats(dev, stats, log_bytes, &phase_of);
        for (size_t r = 0; r < count / per_record; ++r) {
            const size_t task = offset + r * per_record;
            int64_t *dst = sums.data() + (slices_apart > 0 ? task : task / slices) * record;
            for (size_t j = 0; j < record; ++j) {
                int64_t part;  // (a record cut between dispatches: its parts' sum checked too)
                std::memcpy(&part, accum.data() + (r * record + j) * sizeof part, sizeof part);
                if (__builtin_add_overflow(dst[j], part, &dst[j]))
                    dev.reports |= core::kReportFixedSum;
            }
        }
    }
    for (size_t i = 0; i < sums.size(); ++i)
        records[i] += static_cast<double>(sums[i]) / path_units_;
}

ContribEngine::ReplayResult VulkanContribEngine::ReplayLoggedRays(int passes) {
    ReplayResult result;
    DeviceState &dev = devices_[0];
    const size_t n = dev.ray_log.size() / 2;
    if (n == 0) return result;
    if (dev.replay_spirv.empty()) {
        dev.replay_spirv = CompileContribShader(shader_, dev.target, true);
        CHECK(float64_ || !vk::GpuDevice::UsesFloat64(dev.replay_spirv));  // (as Create's)
    }
    const int log = dev.device->Resident(Bytes(dev.ray_log));
    result.rays = n;
    for (int pass = 0; pass < std::max(1, passes); ++pass) {
        double device_s = 0, wall_s = 0;
        for (size_t offset = 0; offset < n; offset += kMaxTasksPerRun) {  // as traces go
            const size_t count = std::min<size_t>(kMaxTasksPerRun, n - offset);
            core::GpuTasks tasks = Tasks(0, 1, 0, 0);
            tasks.task_offset = static_cast<int>(offset);
            tasks.count = static_cast<int>(count);
            std::vector<uint8_t> task_bytes(sizeof tasks), stats(20, 0), none,
                parameter_bytes = parameters_, distances(pass == 0 ? count * AccumBytes() : 0);
            std::memcpy(task_bytes.data(), &tasks, sizeof tasks);
            NamedBindings named = SceneBindings(dev, &none);
            // the first pass's distances come back, to count hits; the others' stay there
            named.Set(core::kBindingAccum,
                      pass == 0 ? G::Accumulator(&distances) : G::Scratch(count * AccumBytes()));
            named.SetDispatch(&task_bytes, &parameter_bytes, &stats);
            named.Set(core::kBindingRayLog, G::OnDevice(log));
            named.SetUnused(
                {core::kBindingRays, core::kBindingScratchItems, core::kBindingScratchRows,
                 core::kBindingSliceSums, core::kBindingPathStarts, core::kBindingPathCount,
                 core::kBindingWalkers, core::kBindingWaveQueue},
                &none);
            const auto start = std::chrono::steady_clock::now();
            dev.device->Run(dev.replay_spirv, static_cast<uint32_t>(count), kGpuLocalSize,
                            named.InOrder(dev.device->RayQueries()));
            wall_s +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const std::vector<double> &seconds = dev.device->LastStageSeconds();
            device_s += seconds.empty() ? 0 : seconds[0];
            for (size_t i = 0; pass == 0 && i < count; ++i) {
                double t;
                if (accumulators_ == GpuAccum::kDouble) {
                    std::memcpy(&t, distances.data() + i * sizeof t, sizeof t);
                } else {
                    float f;
                    std::memcpy(&f, distances.data() + i * sizeof f, sizeof f);
                    t = f;
                }
                result.hits += t >= 0;
            }
        }
        if (pass == 0 || wall_s < result.wall_seconds) result.wall_seconds = wall_s;
        if (pass == 0 || device_s < result.device_seconds) result.device_seconds = device_s;
    }
    return result;
}

}  // namespace

std::unique_ptr<ContribEngine> CreateVulkanContribEngine(
    const FlatScene &scene, const PackedScene &packed, const ContribOptions &options,
    const std::vector<TrackedModifier> &tracked, const MakeContext &make_context,
    const EngineOptions &engine_options, std::string *why) {
    EngineOptions engine = engine_options;
    if (engine.gpu_engine == GpuEngine::kPaths && options.contributions &&
        RadianceExponent(packed) < 0) {
        static std::once_flag said;  // (a run may make several engines)
        std::call_once(said, [] {
            Warning(
                "the GPU's paths engine cannot scale these contributions to its fixed point (a "
                "tracked modifier with a pattern or a mixfunc, or radiances 2^16 apart); using "
                "its tasks engine");
        });
        engine.gpu_engine = GpuEngine::kTasks;
    }
    if (engine.gpu_waves > 0 && engine.gpu_engine != GpuEngine::kPaths) {
        static std::once_flag said;
        std::call_once(said, [] { Warning("-gpu_waves: the tasks engine has none (ignored)"); });
        engine.gpu_waves = 0;
    }
    // A wave's walkers stop between dispatches: their stacks and rows must be kept in storage
    // buffers, which a CPU device has only when asked.
    if (engine.gpu_waves > 0 && engine.scratch == GpuScratch::kOff)
        throw UserError("-gpu_waves needs -gpu_scratch on (the walkers' stacks kept in memory)");
    if (engine.gpu_waves > 0) engine.scratch = GpuScratch::kOn;
    ContribShader shader;
    if (!MakeContribShader(packed, options, tracked, make_context, engine, &shader, why))
        return nullptr;
    std::vector<core::ivec4> tracked_table = packed.tracked;
    for (size_t k = 0; k < tracked_table.size(); ++k)
        tracked_table[k][core::kTrackedFunction] = shader.bin_function[k];
    // lavapipe only when named: on a CPU, the Embree backend is faster.
    std::vector<std::unique_ptr<vk::GpuDevice>> opened = vk::GpuDevice::OpenAll(
        why, engine.device, DeviceTraversal(engine.traversal), engine.NeedsFloat64());
    if (opened.empty()) return nullptr;
    Geometry geometry(scene, packed);
    std::vector<DeviceState> devices;
    for (std::unique_ptr<vk::GpuDevice> &device : opened) {
        DeviceState &dev = devices.emplace_back();
        dev.device = std::move(device);
        const bool cpu = dev.device->IsCpu();
        dev.target.ray_queries = dev.device->RayQueries();
        dev.target.scratch =
            engine.scratch == GpuScratch::kOn || (engine.scratch == GpuScratch::kAuto && !cpu);
        dev.target.inf_nan = dev.device->PreservesInfNan();
        const GpuSpirvOpt opt = engine.spirv_opt;
        dev.target.optimization = opt == GpuSpirvOpt::kSize ? vk::SpirvOptimization::kSize
                                  : opt == GpuSpirvOpt::kNone || (opt == GpuSpirvOpt::kAuto && cpu)
                                      ? vk::SpirvOptimization::kNone
                                      : vk::SpirvOptimization::kPerformance;
        dev.spirv = CompileContribShader(shader, dev.target);
        if (engine.accumulators != GpuAccum::kFloat && engine.gpu_slice_sums &&
            engine.gpu_engine == GpuEngine::kTasks)
            dev.sum_spirv = CompileSliceSumShader(engine.accumulators);
        if (engine.gpu_engine == GpuEngine::kPaths) {
            dev.path_start_bytes =
                vk::GpuDevice::RuntimeArrayStride(dev.spirv, uint32_t(core::kBindingPathStarts));
            CHECK(dev.path_start_bytes > 0);  // contrib.comp's DAYFLUX_PATHS declares them
            dev.walker_bytes =
                vk::GpuDevice::RuntimeArrayStride(dev.spirv, uint32_t(core::kBindingWalkers));
            CHECK(dev.walker_bytes > 0);
        }
        // What we generate holds a double only where the run asked for one: the device was
        // opened without shaderFloat64 otherwise.
        CHECK(engine.NeedsFloat64() ||
              (!vk::GpuDevice::UsesFloat64(dev.spirv) &&
               (dev.sum_spirv.empty() || !vk::GpuDevice::UsesFloat64(dev.sum_spirv))));
        if (!dev.target.ray_queries)  // (our BVH's tables as the shader lays them out)
            CHECK(vk::GpuDevice::RuntimeArrayStride(dev.spirv, uint32_t(core::kBindingScene)) ==
                      sizeof(core::PackedBvhNode) &&
                  vk::GpuDevice::RuntimeArrayStride(dev.spirv, uint32_t(core::kBindingBvhPrims)) ==
                      sizeof(core::PackedBvhEntry));
        if (dev.target.scratch) {
            dev.item_bytes =
                vk::GpuDevice::RuntimeArrayStride(dev.spirv, uint32_t(core::kBindingScratchItems));
            CHECK(dev.item_bytes > 0);  // contrib.comp declares the stack's scratch there
        }
        if (!Upload(packed, tracked_table, geometry, dev, why)) return nullptr;
    }
    return std::make_unique<VulkanContribEngine>(packed, options, engine, std::move(shader),
                                                 std::move(devices));
}

}  // namespace dayflux
