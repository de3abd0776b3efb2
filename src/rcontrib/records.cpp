#include "rcontrib/records.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "matrix/reader.h"
#include "rcontrib/progress.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/pipeline.h"
#include "util/signals.h"
#include "util/strings.h"

namespace dayflux {

// One bad line must not end a long run deep inside the engine (Embree asserts on such rays, a GPU
// gives garbage): NaN, infinity and coordinates beyond any scene are refused.
void CheckInputRay(double ray[6], uint64_t number) {
    constexpr double kLargest = 1e12;  // metres: far beyond any scene, well within float
    for (int k = 0; k < 6; ++k)
        if (!(std::fabs(ray[k]) <= kLargest))
            ErrorExit("input ray " + std::to_string(number) + ": " +
                      (k < 3 ? "origin" : "direction") + " value " + FormatNumber(ray[k]) +
                      (std::isfinite(ray[k]) ? " is out of range" : " is not a number"));
    // The engines normalise directions in float, where a length below 1e-19 is none (a NaN
    // direction, Embree's assertion). RADIANCE's normalize() gives 0 where the squared length
    // underflows in double: such a ray is a zero one (a flush); the others are made unit here.
    double *d = ray + 3;
    const double length2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (length2 == 0) {
        d[0] = d[1] = d[2] = 0;
    } else if (length2 < 1e-30) {
        const double length = std::sqrt(length2);
        for (int k = 0; k < 3; ++k) d[k] /= length;
    }
}

namespace {

// -ff or -fd on rays written as text (the points file of a recipe, say) reads garbage that
// RADIANCE traces without a word: the first ray's bytes all being characters of numbers and
// blanks is a sure sign.
void WarnIfText(InputSource &in, DataFormat format) {
    const size_t bytes = 6 * (format == DataFormat::Float ? 4 : 8);
    const std::string_view first = in.PeekBytes(bytes);
    if (first.size() < bytes) return;
    for (char c : first)
        if (!std::isdigit(static_cast<unsigned char>(c)) &&
            std::string_view(" \t\r\n.+-eE").find(c) == std::string_view::npos)
            return;
    Warning(std::string("the input rays look like text, but -f") +
            (format == DataFormat::Float ? "f" : "d") +
            " reads them as binary numbers (-fa reads text)");
}

}  // namespace

RaySource StandardInputRays(DataFormat format) {
    std::unique_ptr<InputSource> source = InputSource::Open("-");
    if (format == DataFormat::Float || format == DataFormat::Double) WarnIfText(*source, format);
    ReadSpec rs;
    rs.header = false;
    rs.format = format;
    rs.ncols = 1;
    rs.ncomp = 6;
    auto in = std::make_shared<MatrixReader>(std::move(source), rs);
    return [in](double ray[6]) { return in->ReadRow(ray); };
}

namespace {

// A block of input rays traced together. It holds the pieces (segments) of the records it
// touches, so -c 0 or -c 10000 still keeps every thread busy.
struct Segment {
    size_t first = 0, count = 0;  // rays of the block
    bool ends_record = false;
    double scale = 1;  // 1/-c, applied when the record ends
};
struct Block {
    std::vector<double> rays;  // 6 per ray; a zero direction is a flush, not traced
    uint64_t first_ray = 0;
    std::vector<Segment> segments;
    std::vector<std::vector<double>> sums;  // per segment
    std::vector<std::vector<double>> vars;  // per segment, with -se: variance of the sums
    bool flush = false;                     // a zero ray: flush the outputs after
};

// Reads input rays into blocks of at most `block_rays`, ending records after -c rays, after -y
// records, or (partial) at the end of input.
class RayReader {
  public:
    RayReader(const RcontribOptions &o, size_t block_rays, RaySource rays)
        : o_(o), block_rays_(block_rays), rays_(std::move(rays)) {
        if (!rays_) rays_ = StandardInputRays(o.in);
        wanted_ = o.yres > 0 ? static_cast<long>(o.yres) * std::max(o.xres, 1) : -1;
        ray_base_ = static_cast<uint64_t>(std::max(o.first_record, 0L)) *
                    static_cast<uint64_t>(std::max(o.accumulate, 1));
    }
    long Wanted() const { return wanted_; }

    // Skips the rays of `records` records (-r).
    void Skip(long records) {
        const long skip = records * std::max(o_.accumulate, 1);
        double ray[6];
        for (long k = 0; k < skip; ++k)
            if (!rays_(ray)) ErrorExit("unexpected EOF on input");
        next_ray_ = static_cast<uint64_t>(skip);
        ended_ = records;
    }

    std::unique_ptr<Block> Next() {
        if (done_) return nullptr;
        auto b = std::make_unique<Block>();
        b->first_ray = ray_base_ + next_ray_;
        double ray[6];
        while (b->rays.size() / 6 < block_rays_) {
            if (StopOnSignals::Requested()) {
                done_ = true;
                break;
            }
            if (wanted_ >= 0 && ended_ >= wanted_) {
                done_ = true;
                break;
            }
            if (!rays_(ray)) {
                // A terminal's Ctrl-C also ends the program writing the rays: its end is not
                // the end of the input.
                if (!StopOnSignals::Requested()) EndOfInput(b.get());
                done_ = true;
                break;
            }
            CheckInputRay(ray, next_ray_ + b->rays.size() / 6 + skipped_ + 1);
            const bool zero = ray[3] == 0 && ray[4] == 0 && ray[5] == 0;
            if (zero && o_.accumulate <= 0) {
                if (!warned_dummy_) Warning("dummy ray(s) ignored during accumulation");
                warned_dummy_ = true;
                ++skipped_;
                continue;
            }
            AddRay(b.get(), ray);
            if (o_.accumulate > 0 && in_record_ == o_.accumulate)
                EndRecord(b.get(), o_.accumulate > 1 ? 1.0 / o_.accumulate : 1);
            // The block ends at a flush: a caller feeding rays through a pipe may be waiting for
            // the records so far before it sends more. Not for pictures (-x and -y), where
            // RADIANCE does not flush either and vwrays' zero rays would make blocks of one.
            if (zero && (o_.yres <= 0 || o_.xres <= 1)) {
                b->flush = true;
                break;
            }
        }
        if (b->segments.empty()) return nullptr;
        next_ray_ += b->rays.size() / 6;
        return b;
    }

  private:
    void AddRay(Block *b, const double *ray) {
        const size_t n = b->rays.size() / 6;
        b->rays.insert(b->rays.end(), ray, ray + 6);
        if (b->segments.empty() || b->segments.back().ends_record)
            b->segments.push_back(Segment{n, 0, false, 1});
        ++b->segments.back().count;
        ++in_record_;
    }
    void EndRecord(Block *b, double scale) {
        if (b->segments.empty() || b->segments.back().ends_record)
            b->segments.push_back(Segment{b->rays.size() / 6, 0, false, 1});
        b->segments.back().ends_record = true;
        b->segments.back().scale = scale;
        in_record_ = 0;
        ++ended_;
    }
    void EndOfInput(Block *b) {
        if (o_.accumulate <= 0) {
            EndRecord(b, 1);  // -c 0: one record of every ray
        } else if (in_record_ > 0) {
            // A shard cut inside a record would merge into a matrix with a row too many.
            if (o_.first_record >= 0)
                ErrorExit("the input ends " + std::to_string(in_record_) +
                          " rays into a record of " + std::to_string(o_.accumulate) +
                          " (-c): a shard (-first_record) must hold whole records");
            Warning("partial accumulation in final record");
            EndRecord(b, o_.accumulate > 1 ? 1.0 / static_cast<double>(in_record_) : 1);
        }
    }

    const RcontribOptions &o_;
    const size_t block_rays_;
    RaySource rays_;
    long wanted_;
    uint64_t ray_base_ = 0;  // -first_record: the rays of the records before this input's
    uint64_t next_ray_ = 0;
    long ended_ = 0;        // records ended
    long in_record_ = 0;    // rays in the record being read
    uint64_t skipped_ = 0;  // dummy rays dropped (-c 0), for the numbers in messages
    bool done_ = false, warned_dummy_ = false;
};

// The block traced (per replica with -se), then summed per segment.
void TraceBlock(ContribEngine &engine, int replicas, Block &b) {
    const size_t n = 3 * static_cast<size_t>(engine.Columns()), nrays = b.rays.size() / 6;
    const bool replicate = replicas > 1;
    std::vector<double> sums(nrays * n, 0.0), vars(replicate ? nrays * n : 0, 0.0);
    TraceReplicas(engine, b.rays.data(), nrays, b.first_ray, replicas, sums.data(),
                  replicate ? vars.data() : nullptr);
    b.sums.resize(b.segments.size());
    b.vars.resize(replicate ? b.segments.size() : 0);
    for (size_t i = 0; i < b.segments.size(); ++i) {
        const Segment &seg = b.segments[i];
        b.sums[i].assign(n, 0.0);
        if (replicate) b.vars[i].assign(n, 0.0);
        for (size_t ray = seg.first; ray < seg.first + seg.count; ++ray)
            for (size_t j = 0; j < n; ++j) {
                b.sums[i][j] += sums[ray * n + j];
                if (replicate) b.vars[i][j] += vars[ray * n + j];
            }
    }
}

// Sums segments into records and writes each as it ends, in order.
class RecordWriter {
  public:
    RecordWriter(RcontribOutputs &outputs, int ncols, bool replicate, long written,
                 ProgressReport &progress)
        : outputs_(outputs),
          replicate_(replicate),
          written_(written),
          progress_(progress),
          pending_(3 * static_cast<size_t>(ncols), 0.0),
          pending_var_(pending_.size(), 0.0),
          standard_error_(pending_.size(), 0.0) {}
    long Written() const { return written_; }

    void Consume(const Block &b) {
        for (size_t i = 0; i < b.segments.size(); ++i) {
            for (size_t k = 0; k < pending_.size(); ++k) pending_[k] += b.sums[i][k];
            if (replicate_)
                for (size_t k = 0; k < pending_.size(); ++k) pending_var_[k] += b.vars[i][k];
            if (b.segments[i].ends_record) EndRecord(b.segments[i].scale);
        }
        if (b.flush) outputs_.Flush();
    }

  private:
    void EndRecord(double scale) {
        if (scale != 1)
            for (double &v : pending_) v *= scale;
        for (size_t k = 0; k < pending_.size(); ++k)
            standard_error_[k] = std::sqrt(pending_var_[k]) * scale;
        outputs_.Write(pending_, standard_error_);
        std::fill(pending_.begin(), pending_.end(), 0.0);
        std::fill(pending_var_.begin(), pending_var_.end(), 0.0);
        progress_.Update(++written_);
    }

    RcontribOutputs &outputs_;
    const bool replicate_;
    long written_;
    ProgressReport &progress_;
    std::vector<double> pending_, pending_var_, standard_error_;
};

}  // namespace

void TraceRecords(const RcontribOptions &o, ContribEngine &engine, RcontribOutputs &outputs,
                  RaySource rays) {
    RayReader reader(o, engine.BatchRays(), std::move(rays));
    const long wanted = reader.Wanted(), recovered = outputs.Recovered();
    if (recovered > 0) {
        if (wanted >= 0 && recovered >= wanted) {
            Warning("output appears to be complete");
            return;
        }
        reader.Skip(recovered);
    }
    const bool replicate = !o.stderr_file.empty();
    ProgressReport progress(o.report_seconds, o.progress, wanted);
    RecordWriter writer(outputs, engine.Columns(), replicate, recovered, progress);
    OrderedPipeline<Block>([&] { return reader.Next(); },
                           [&](Block &b) { TraceBlock(engine, replicate ? kReplicas : 1, b); },
                           [&](Block &b) { writer.Consume(b); });
    if (const int sig = StopOnSignals::Requested())
        throw Interrupted(sig, std::string("stopped by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                                   " after " + std::to_string(writer.Written()) + " records");
    if (wanted > 0 && writer.Written() < wanted)
        ErrorExit("unexpected end of input: " + std::to_string(writer.Written()) + " of " +
                  std::to_string(wanted) + " records");
}

}  // namespace dayflux
