#include "interrupt.h"

#include <csignal>

#include <unistd.h>

#include "output/image_output.h"

namespace whitted::cli {

InterruptState& interrupts() {
    static InterruptState state;
    return state;
}

namespace {

/// Writes a fixed message with write(2), the async-signal-safe way.
template <size_t N>
void say(const char (&message)[N]) {
    const ssize_t ignored = ::write(STDERR_FILENO, message, N - 1);
    (void)ignored;
}

extern "C" void on_interrupt(int sig) {
    InterruptState& s = interrupts();
    s.last_signal.store(sig);
    const bool first = s.signals.fetch_add(1) == 0;
    if (first && (s.writing.load() || s.rendering.load())) {
        s.stop.store(true);
        if (!s.writing.load())
            say("\nwhitted: interrupted: finishing the tiles in flight, then writing what is done "
                "(interrupt again to quit at once)\n");
        return;
    }
    remove_partial_output();
    say("\nwhitted: interrupted: exiting at once; earlier files are left as they were\n");
    ::_exit(128 + sig);
}

}  // namespace

void install_interrupt_handlers() {
    struct sigaction sa {};
    sa.sa_handler = &on_interrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    // Under mpirun, ^C and SIGTERM end the whole job at once; SIGUSR1 it passes on to the ranks
    // and leaves the job running: `kill -USR1 <mpirun>` stops a distributed render gracefully.
    if (interrupts().mpi) sigaction(SIGUSR1, &sa, nullptr);
}

void ignore_interrupts() {
    std::signal(SIGINT, SIG_IGN);
    std::signal(SIGTERM, SIG_IGN);
    std::signal(SIGUSR1, SIG_IGN);
}

}  // namespace whitted::cli
