#include <atomic>

#include "skybake/core.h"

namespace skybake {

namespace {
std::atomic<bool> g_quiet{false};
}

const char* version() { return SKYBAKE_VERSION_STRING; }

bool build_has_cuda() {
#if defined(SKYBAKE_HAS_CUDA)
    return true;
#else
    return false;
#endif
}

#if !defined(SKYBAKE_HAS_CUDA)
int cuda_device_count() { return 0; }
std::string cuda_device_name() { return {}; }
#endif

void set_quiet(bool q) { g_quiet.store(q); }
bool quiet() { return g_quiet.load(); }

} // namespace skybake
