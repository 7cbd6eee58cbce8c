// A progress bar on stderr. It is drawn only when stderr is a terminal and
// quiet mode is off, and redrawn at most every 100 ms. advance() is thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace skybake {

class Progress {
public:
    Progress(std::string label, std::uint64_t total);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void advance(std::uint64_t n = 1);
    void finish();
    bool enabled() const { return enabled_; }

private:
    void draw(std::uint64_t done, bool final);

    std::string label_;
    std::uint64_t total_;
    std::atomic<std::uint64_t> done_{0};
    bool enabled_;
    bool finished_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, last_draw_;
};

} // namespace skybake
