#include "rcontrib/progress.h"

#include <cstdio>

namespace dayflux {

namespace {
double Seconds(std::chrono::steady_clock::duration d) {
    return std::chrono::duration<double>(d).count();
}
}  // namespace

ProgressReport::ProgressReport(double radiance_interval, bool progress, long total)
    : interval_(radiance_interval),
      progress_(progress),
      total_(total),
      start_(Clock::now()),
      last_radiance_(start_),
      last_progress_(start_) {}

void ProgressReport::Update(long done) {
    if (interval_ <= 0 && !progress_) return;
    const auto now = Clock::now();
    const double elapsed = Seconds(now - start_);
    if (interval_ > 0 && total_ > 0 && Seconds(now - last_radiance_) >= interval_) {
        std::fprintf(stderr, "%.2f%% done after %.3f hours\n", 100.0 * done / total_,
                     elapsed / 3600.0);
        last_radiance_ = now;
    }
    if (progress_ && (Seconds(now - last_progress_) >= 1.0 || (total_ > 0 && done == total_))) {
        const double rate = elapsed > 0 ? done / elapsed : 0;
        if (total_ > 0 && rate > 0)
            std::fprintf(stderr,
                         "rcontrib-gpu: %ld of %ld records (%.1f%%), %.0f s, about %.0f s left\n",
                         done, total_, 100.0 * done / total_, elapsed, (total_ - done) / rate);
        else
            std::fprintf(stderr, "rcontrib-gpu: %ld records, %.0f s, %.1f records/s\n", done,
                         elapsed, rate);
        last_progress_ = now;
    }
}

}  // namespace dayflux
