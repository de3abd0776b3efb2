#include "util/signals.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>

namespace dayflux {

namespace {

volatile std::sig_atomic_t requested_signal = 0;
struct sigaction saved_int, saved_term;
// A pipe the handler writes a byte to, so that a reader waiting in poll() wakes (a read() would
// be restarted); its read end while a StopOnSignals lives, else -1.
int wake_pipe[2] = {-1, -1};
int wake_fd = -1;

void RequestStop(int sig) {
    requested_signal = sig;
    const int saved_errno = errno;
    if (wake_pipe[1] >= 0) {
        const char byte = 1;
        [[maybe_unused]] const ssize_t n = write(wake_pipe[1], &byte, 1);
    }
    errno = saved_errno;
}

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
    if (wake_pipe[0] < 0 && pipe2(wake_pipe, O_CLOEXEC | O_NONBLOCK) != 0)
        wake_pipe[0] = wake_pipe[1] = -1;
    wake_fd = wake_pipe[0];
    Install(SIGINT, &saved_int);
    Install(SIGTERM, &saved_term);
}

StopOnSignals::~StopOnSignals() {
    wake_fd = -1;
    sigaction(SIGINT, &saved_int, nullptr);
    sigaction(SIGTERM, &saved_term, nullptr);
}

int StopOnSignals::Requested() { return requested_signal; }

int StopOnSignals::WakeFd() { return wake_fd; }

void IgnoreFileSizeSignal() { std::signal(SIGXFSZ, SIG_IGN); }

void RaiseDefault(int sig) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    std::_Exit(128 + sig);  // if the signal was blocked
}

}  // namespace dayflux
