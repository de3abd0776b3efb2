// Signals that end a long run. While a StopOnSignals lives, the first SIGINT or SIGTERM only asks
// the run to stop (the blocks in flight finish and their records are written and kept for -r);
// a second one ends the program at once, as the default action would have.
#pragma once

#include <string>

#include "util/errors.h"

namespace dayflux {

class StopOnSignals {
  public:
    StopOnSignals();
    ~StopOnSignals();
    StopOnSignals(const StopOnSignals &) = delete;
    StopOnSignals &operator=(const StopOnSignals &) = delete;

    // The signal that asked to stop, or 0.
    static int Requested();
    // While one lives: a descriptor that becomes readable when a stop is asked for, for readers
    // that wait on a pipe (poll() it beside theirs); else -1.
    static int WakeFd();
};

// A run that stopped on a signal: RunTool prints the message and ends the program by the same
// signal (so a calling shell script stops too, as it would for a program killed by it).
class Interrupted : public UserError {
  public:
    Interrupted(int signal, const std::string &message) : UserError(message), signal_(signal) {}
    int Signal() const { return signal_; }

  private:
    int signal_;
};

// For RunTool: a file-size limit (ulimit -f) gives a write error with a message, not SIGXFSZ's
// core dump.
void IgnoreFileSizeSignal();

// Ends the program by signal sig with its default action (after output has been flushed).
[[noreturn]] void RaiseDefault(int sig);

}  // namespace dayflux
