// skybake/progress.h: how long operations (bakes, training, renders, table
// builds) report their progress. By default a bar on stderr, drawn only when
// stderr is a terminal and quiet mode is off. A caller that shows progress
// its own way (a Python notebook, Blender's status bar) installs a callback;
// every operation then reports to it instead, at most every 100 ms and once
// at the end.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>

namespace skybake {

struct ProgressEvent {
    std::string_view label;  // "bake", "train", "render", ...
    std::uint64_t done = 0;  // units of work done
    std::uint64_t total = 0; // units of work in all (0: unknown)
    double seconds = 0.0;    // since the operation began
    std::string_view status; // a short note, e.g. "loss 0.0213"; may be empty
    bool finished = false;   // the last event of the operation
};

using ProgressCallback = std::function<void(const ProgressEvent&)>;

// Installs `callback` for every operation that starts afterwards, and returns
// the one it replaces. An empty callback restores the bar. The callback may be
// called from any worker thread, one call at a time; an exception it throws
// (skybake::Interrupted, say, to cancel) stops the operation and is rethrown
// to its caller.
ProgressCallback set_progress_callback(ProgressCallback callback);

} // namespace skybake
