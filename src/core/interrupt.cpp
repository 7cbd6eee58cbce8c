#include "skybake/interrupt.h"

#include <atomic>
#include <csignal>
#include <cstring>

#include <unistd.h>

namespace skybake {

namespace {

std::atomic<int> g_signal{0};

extern "C" void on_signal(int sig) {
    if (g_signal.exchange(sig) != 0) // the second signal: stop now
        _exit(128 + sig);
}

} // namespace

Interrupted::Interrupted(int signal)
    : Error(std::string("interrupted by ") +
            (signal == SIGINT    ? "SIGINT"
             : signal == SIGTERM ? "SIGTERM"
                                 : "a signal") +
            "; no output was written"),
      signal_(signal) {}

void install_interrupt_handlers() {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; // no SA_RESTART: a blocking read returns EINTR, so its loop can look
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

int interrupt_signal() {
    return g_signal.load(std::memory_order_relaxed);
}

void request_interrupt(int signal) noexcept {
    g_signal.store(signal, std::memory_order_relaxed);
}

void clear_interrupt() noexcept {
    g_signal.store(0, std::memory_order_relaxed);
}

void check_interrupted() {
    if (const int s = g_signal.load(std::memory_order_relaxed))
        throw Interrupted(s);
}

} // namespace skybake
