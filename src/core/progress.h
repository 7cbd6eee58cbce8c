// A progress bar on stderr: the fraction done, the rate, the time elapsed and
// the time left, and an optional status (a training loss, say). It is drawn
// only when stderr is a terminal and quiet mode is off, and redrawn at most
// every 100 ms; with a callback installed (skybake/progress.h) the same
// events go to the callback instead. advance() is thread-safe, and throws skybake::Interrupted once
// SIGINT or SIGTERM has arrived (skybake/interrupt.h), so every loop with a
// progress bar can be stopped cleanly.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "skybake/progress.h"

namespace skybake {

class Progress {
public:
    Progress(std::string label, std::uint64_t total);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void advance(std::uint64_t n = 1);
    // A short text drawn after the times, e.g. "loss 0.0213".
    void set_status(std::string status);
    void finish();
    bool enabled() const { return enabled_; }

private:
    void draw(std::uint64_t done, bool final);
    void report(std::uint64_t done, bool final);

    std::string label_, status_;
    std::uint64_t total_;
    std::atomic<std::uint64_t> done_{0};
    ProgressCallback callback_; // the one installed when the operation began, or empty
    bool enabled_;
    bool finished_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, last_draw_;
};

} // namespace skybake
