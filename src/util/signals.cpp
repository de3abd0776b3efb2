#include "util/signals.h"

#include <csignal>
#include <cstdlib>

namespace dayflux {

namespace {

volatile std::sig_atomic_t requested_signal = 0;
struct sigaction saved_int, saved_term;

void RequestStop(int sig) { requested_signal = sig; }

void Install(int sig, struct sigaction *saved) {
    struct sigaction sa {};
    sa.sa_handler = RequestStop;
    sigemptyset(&sa.sa_mask);
    // SA_RESETHAND: the second signal gets the default action. SA_RESTART: a read in progress
    // goes on, so a signal never looks like the end of the input.
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(sig, &sa, saved);
    // A signal the caller ignores (SIGINT for a shell's background job, nohup) stays ignored.
    if (saved->sa_handler == SIG_IGN) sigaction(sig, saved, nullptr);
}

}  // namespace

StopOnSignals::StopOnSignals() {
    requested_signal = 0;
    Install(SIGINT, &saved_int);
    Install(SIGTERM, &saved_term);
}

StopOnSignals::~StopOnSignals() {
    sigaction(SIGINT, &saved_int, nullptr);
    sigaction(SIGTERM, &saved_term, nullptr);
}

int StopOnSignals::Requested() { return requested_signal; }

void IgnoreFileSizeSignal() { std::signal(SIGXFSZ, SIG_IGN); }

void RaiseDefault(int sig) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    std::_Exit(128 + sig);  // if the signal was blocked
}

}  // namespace dayflux
