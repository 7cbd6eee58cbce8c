#include "core/progress.h"

#include <cstdio>
#include <unistd.h>

#include "skybake/core.h"
#include "skybake/interrupt.h"

namespace skybake {

namespace {
std::mutex g_callback_mutex;
ProgressCallback g_callback;

ProgressCallback current_callback() {
    std::lock_guard lock(g_callback_mutex);
    return g_callback;
}
} // namespace

ProgressCallback set_progress_callback(ProgressCallback callback) {
    std::lock_guard lock(g_callback_mutex);
    std::swap(g_callback, callback);
    return callback;
}

Progress::Progress(std::string label, std::uint64_t total)
    : label_(std::move(label)), total_(total), callback_(current_callback()) {
    enabled_ = callback_ ? true : (!quiet() && isatty(STDERR_FILENO) == 1);
    start_ = last_draw_ = std::chrono::steady_clock::now();
}

Progress::~Progress() {
    try {
        finish();
    } catch (...) { // a callback's exception cannot leave a destructor
    }
}

void Progress::advance(std::uint64_t n) {
    check_interrupted();
    const std::uint64_t done = done_.fetch_add(n) + n;
    if (!enabled_)
        return;
    const auto now = std::chrono::steady_clock::now();
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || finished_ || now - last_draw_ < std::chrono::milliseconds(100))
        return;
    last_draw_ = now;
    report(done, false);
}

void Progress::set_status(std::string status) {
    std::lock_guard lock(mutex_);
    status_ = std::move(status);
}

void Progress::finish() {
    std::lock_guard lock(mutex_);
    if (finished_)
        return;
    finished_ = true;
    if (enabled_)
        report(done_.load(), true);
}

void Progress::report(std::uint64_t done, bool final) {
    if (!callback_) {
        draw(done, final);
        return;
    }
    ProgressEvent e;
    e.label = label_;
    e.done = done;
    e.total = total_;
    e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    e.status = status_;
    e.finished = final;
    callback_(e);
}

void Progress::draw(std::uint64_t done, bool final) {
    const double frac = total_ ? double(done > total_ ? total_ : done) / double(total_) : 1.0;
    const int width = 30;
    const int filled = int(frac * width + 0.5);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    char bar[width + 1];
    for (int i = 0; i < width; ++i)
        bar[i] = i < filled ? '#' : '.';
    bar[width] = 0;
    const double rate = secs > 0.0 ? double(done) / secs : 0.0;
    const char* unit = "";
    double shown = rate;
    for (const char* u : {"k", "M", "G"})
        if (shown >= 1000.0) {
            shown /= 1000.0;
            unit = u;
        }
    char left[32] = "";
    if (!final && frac > 0.0 && frac < 1.0)
        std::snprintf(left, sizeof left, ", %.0fs left", secs * (1.0 - frac) / frac);
    std::fprintf(stderr, "\r%s [%s] %5.1f%% %6.1f%s/s %6.1fs%s%s%s\x1b[K", label_.c_str(), bar, frac * 100.0, shown,
                 unit, secs, left, status_.empty() ? "" : "  ", status_.c_str());
    if (final)
        std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

} // namespace skybake
