#include "core/parallel.h"

#include <memory>
#include <mutex>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "skybake/core.h"

namespace skybake {

namespace {
std::mutex g_control_mutex;
std::unique_ptr<tbb::global_control> g_control;
int g_threads = 0;
} // namespace

void set_thread_count(int threads) {
    std::lock_guard lock(g_control_mutex);
    g_control.reset();
    g_threads = threads > 0 ? threads : 0;
    if (g_threads > 0)
        g_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                          static_cast<std::size_t>(g_threads));
}

int thread_count() {
    std::lock_guard lock(g_control_mutex);
    return g_threads > 0 ? g_threads : tbb::info::default_concurrency();
}

void parallel_for(std::size_t count, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
    if (count == 0)
        return;
    if (grain == 0)
        grain = 1;
    if (count <= grain) {
        body(0, count);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

} // namespace skybake
