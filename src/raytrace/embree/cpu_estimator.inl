// One thread's estimator on the CPU, the class DAYFLUX_ESTIMATOR: the core's state (its
// fragments, included in this class's body, so that their globals are this object's members)
// and what the CPU driver gives the core. cpu_contrib.cpp includes this once per set of the
// core's features (DAYFLUX_ASUB, DAYFLUX_BSDF, ...) it compiles, as the GPU compiles a shader per
// scene: a ray then carries no field its scene never uses.
class DAYFLUX_ESTIMATOR final : public CpuEstimator {
  public:
    // paths: the first hemisphere's cells walked at once (RunCells); a lane's estimator shares
    // its owner's bins (lanes run in turns on one thread).
    DAYFLUX_ESTIMATOR(const CpuScene &s, int paths, CpuBins *shared_bins = nullptr)
        : scene_(s),
          params(MakeParameters<CpuParameters>(s.packed, s.options)),
          surfaces(s.packed.surfaces.data()),
          sources(s.packed.sources.data()),
          relays(s.packed.relays.data()),
          receivers(s.packed.receivers.data()),
          klems(s.packed.klems.data()),
          tracked(s.packed.tracked.data()),
          centre_(s.packed.centre[0], s.packed.centre[1], s.packed.centre[2]),
          own_bins_(shared_bins ? nullptr : std::make_unique<CpuBins>(s)),
          bins_(shared_bins ? shared_bins : own_bins_.get()) {
        dropped = 0;
        reports = 0;
        // (only -I's sensors have first-hemisphere cells to hand out)
        if (paths > 1 && s.options.irradiance) MakeLanes(std::min(paths, kMaxPaths));
    }
    ~DAYFLUX_ESTIMATOR() override {
        for (DAYFLUX_ESTIMATOR *lane : lanes_) lane->~DAYFLUX_ESTIMATOR();
    }
    DAYFLUX_ESTIMATOR(const DAYFLUX_ESTIMATOR &) = delete;
    DAYFLUX_ESTIMATOR &operator=(const DAYFLUX_ESTIMATOR &) = delete;

    void Trace(const double org[3], const double dir[3], uint64_t index, int replica,
               double *records, int slices) override {
        const real3 o = real3(org[0], org[1], org[2]) - centre_;
        const real3 d = normalize(real3(dir[0], dir[1], dir[2]));
        const uint n = static_cast<uint>(slices);
        // Each slice's share of the light sources, then the hemisphere whole, each cell's path
        // adding to its slice's record (the same numbers as a task a slice would draw).
        for (uint s = 0; s < n; ++s) {
            record_ = SliceRecord(records, static_cast<int>(s));
            StartInput(o, d, static_cast<uint>(index), static_cast<uint>(replica), s, n);
            RunStack();
        }
        Item cells;
        if (InputCells(o, d, 0u, 1u, cells)) RunCells(cells, records, n);
        Report();
        for (auto &lane : lanes_) lane->Report();
    }

  private:
    static constexpr int kMaxPaths = 16;

    // n lanes in one block, each at another offset within a page: objects of 1.6 MB from malloc
    // all start at one offset of their pages, so the lanes' hot fields (the stack's first items,
    // the random state) fell in the same sets of the L1 cache, and two threads on one core ran
    // 40 % slower than one after the other.
    void MakeLanes(int n) {
        static_assert(alignof(DAYFLUX_ESTIMATOR) <= alignof(std::max_align_t));
        constexpr size_t kPage = 4096, kShift = 5 * 64;
        const size_t stride = (sizeof(DAYFLUX_ESTIMATOR) + kPage - 1) / kPage * kPage + kShift;
        lane_memory_.reset(new std::byte[stride * static_cast<size_t>(n) + kShift]);
        for (int k = 0; k < n; ++k)
            lanes_.push_back(new (lane_memory_.get() + kShift + stride * static_cast<size_t>(k))
                                 DAYFLUX_ESTIMATOR(scene_, 1, bins_));
    }

    // The core's reports and dropped items, to the engine.
    void Report() {
        if (reports != 0u) scene_.reports.fetch_or(reports), reports = 0;
        if (dropped != 0u) scene_.dropped.fetch_add(dropped), dropped = 0;
    }

    // ---- the core (its parameters: the member `params`), and its sizes, larger than the GPU's,
    // where memory is cheap (-ss up to 100 at -ab 10, -ad up to 16M, mixfuncs 63 deep).
#define STACK_SIZE 4096
#define MAXN 4096
#define DEEP_N 256
#define DEEP_LEVELS 16
#define MIX_STACK 64
    // The core's fragments in this order (GLSL declares before use; C++ keeps the same order).
    // clang-format off
#include "raytrace/core/rays.inl"
#include "raytrace/core/hemisphere.inl"
#include "raytrace/core/klems.inl"
#include "raytrace/core/bsdf.inl"
#include "raytrace/core/direct.inl"
#include "raytrace/core/materials.inl"
#include "raytrace/core/walk.inl"
    // clang-format on
#undef STACK_SIZE
#undef MAXN
#undef DEEP_N
#undef DEEP_LEVELS
#undef MIX_STACK
#undef STACK
#undef ROW0
#undef ROWD

    // ---- the driver's walk
    // The first hemisphere's cells: one after the other on this stack, or several paths at once,
    // each lane (an estimator of its own, adding to the record of its cell's slice) walking one
    // cell's path, and the lanes' next rays traced together (in Embree's packets, where a ray
    // costs less than alone, even from different points). The same random numbers as one after
    // the other; the record's sums are added in another order.
    void RunCells(Item cells, double *records, uint slices) {
        const int per_slice = StepsPerSlice(cells, slices);
        if (lanes_.empty()) {  // a cell at a time, each on to its slice's record
            Ray r;
            uint state;
            bool last;
            while (NextCell(cells, r, state, last)) {
                record_ = SliceRecord(records, (cells.next - 1) / per_slice);
                StartCellPath(r, state, last);
                RunStack();
            }
            return;
        }
        int pending[kMaxPaths];  // each lane's ray to trace: its slot on the lane's stack
        bool busy[kMaxPaths] = {};
        TraceRay rays[kMaxPaths];
        TraceHit hits[kMaxPaths];
        int lane_of[kMaxPaths];
        const int lanes = static_cast<int>(lanes_.size());
        bool cells_left = true;
        for (;;) {
            int n = 0;
            for (int l = 0; l < lanes; ++l) {
                if (!busy[l] && cells_left)
                    busy[l] = cells_left =
                        StartCell(cells, records, per_slice, *lanes_[l], &pending[l]);
                if (!busy[l]) continue;
                const Ray &r = lanes_[l]->stack[pending[l]].r;
                rays[n] = scene_.RayFrom(r.org, r.dir, r.from);
                lane_of[n++] = l;
            }
            if (n == 0) return;
            scene_.backend.Closest(rays, hits, static_cast<size_t>(n));
            for (int k = 0; k < n; ++k) {
                DAYFLUX_ESTIMATOR &lane = *lanes_[lane_of[k]];
                int &at = pending[lane_of[k]];
                Hit h;
                const bool met = HitOf(hits[k], h);
                Ray r = lane.stack[at].r;
                lane.ShadeMet(r, met, h);
                busy[lane_of[k]] = lane.NextRay(at);
            }
        }
    }

    // Starts the next cell's path on lane, its first ray to trace in slot *at; false once no cell
    // is left.
    // (per_slice: the hemisphere's StepsPerSlice, each cell's record its slice's)
    bool StartCell(Item &cells, double *records, int per_slice, DAYFLUX_ESTIMATOR &lane, int *at) {
        Ray r;
        uint state;
        bool last;
        while (NextCell(cells, r, state, last)) {
            lane.record_ = SliceRecord(records, (cells.next - 1) / per_slice);
            lane.StartCellPath(r, state, last);
            if (lane.NextRay(*at)) return true;
        }
        return false;
    }

    // Slice k's record of records (a record a slice, ray by ray).
    double *SliceRecord(double *records, int k) const {
        return records + 3 * static_cast<size_t>(scene_.packed.columns) * static_cast<size_t>(k);
    }

    // ---- what the core asks of its driver (raytrace/core/README.md)
    bool Intersect(const Ray &r, Hit &h) const {
        const TraceRay tr = scene_.RayFrom(r.org, r.dir, r.from);
        TraceHit th;
        scene_.backend.Closest(&tr, &th, 1);
        return HitOf(th, h);
    }
    // The backend's hit as the core's, its surface in the tables, recentred (false where the ray
    // met nothing).
    bool HitOf(const TraceHit &th, Hit &h) const {
        if (!th.hit) return false;
        const FlatScene &flat = scene_.flat;
        const PackedScene &packed = scene_.packed;
        if (th.shape >= 0) {
            const PackedShape &shape = packed.shapes[packed.shape_of[th.shape]];
            h.object = flat.shapes[th.shape].object;
            h.surface = shape.surface;
            h.planar = shape.kind == kShapeRing;  // (as the GPU's Intersect decides it)
        } else {
            h.object = flat.triangle_object[th.triangle];
            h.surface = packed.triangles[th.triangle].surface;
            h.planar = packed.triangles[th.triangle].planar != 0;
        }
        h.point = real3(th.point[0], th.point[1], th.point[2]) - centre_;
        h.normal = real3(th.normal[0], th.normal[1], th.normal[2]);
        h.t = th.t;
        return true;
    }
    // The blockers ahead of a direct item, asked once for all its sources (CpuScene::BlockedAhead)
    // and kept while its steps run (nothing else asks between them); Blocked answers from them
    // where the same ray is asked.
    void BlockersAhead(real3 org, real3 normal, int from, bool front, bool back, int first,
                       int end) {
        if (ahead_valid_ && from == ahead_from_ && org == ahead_org_ && first >= ahead_first_ &&
            end <= ahead_end_)
            return;
        if (ahead_.size() < static_cast<size_t>(params.nsources)) ahead_.resize(params.nsources);
        ahead_valid_ = scene_.BlockedAhead(org, normal, from, front, back, first, end,
                                           ahead_.data(), &ahead_buffers_);
        ahead_org_ = org;
        ahead_from_ = from;
        ahead_first_ = first;
        ahead_end_ = end;
    }
    bool Blocked(real3 org, real3 dir, int from, int source) const {
        if (ahead_valid_ && from == ahead_from_ && org == ahead_org_ && source >= ahead_first_ &&
            source < ahead_end_ && ahead_[source] != 0 && dir == XYZ(sources[source].dir))
            return ahead_[source] == 2;
        return scene_.Blocked(org, dir, from);
    }
    double BinOf(int k, int source) { return bins_->Value(k, source, cal_chan); }
    real3 PatternRGB(int k) const { return scene_.PatternRGB(k, cal_chan); }
    void AddToRecord(int column, real3 v) {
        double *at = record_ + 3 * static_cast<size_t>(column);
        at[0] += v.x, at[1] += v.y, at[2] += v.z;
    }

    // ---- the run, as the core reads it
    const CpuScene &scene_;
    const CpuParameters params;
    const PackedSurface *surfaces;
    const PackedSource *sources;
    const vec4 *relays;
    const vec4 *receivers;
    const float *klems;
    const ivec4 *tracked;
    real3 centre_;
    double *record_ = nullptr;
    std::unique_ptr<CpuBins> own_bins_;
    CpuBins *bins_;                             // own_bins_, or the owner's of a lane
    std::unique_ptr<std::byte[]> lane_memory_;  // MakeLanes's
    std::vector<DAYFLUX_ESTIMATOR *> lanes_;    // RunCells's, if any, in lane_memory_
    // BlockersAhead's answers, for the origin and object they were asked from
    bool ahead_valid_ = false;
    real3 ahead_org_ = real3(0);
    int ahead_from_ = -1;
    int ahead_first_ = 0, ahead_end_ = 0;
    std::vector<uint8_t> ahead_;
    AheadBuffers ahead_buffers_;
};
