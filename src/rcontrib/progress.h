// Progress on stderr: RADIANCE's -t line ("P% done after H hours", only when -y gives the
// total) and our -progress line with the rate and the time left.
#pragma once

#include <chrono>

namespace dayflux {

class ProgressReport {
  public:
    ProgressReport(double radiance_interval, bool progress, long total);
    // done: records written so far.
    void Update(long done);

  private:
    using Clock = std::chrono::steady_clock;
    double interval_;
    bool progress_;
    long total_;
    Clock::time_point start_, last_radiance_, last_progress_;
};

}  // namespace dayflux
