// Stand-ins for the window when the build has none (GLFW or Dear ImGui was
// not found when it was configured; see src/render/render.cmake).
#if !defined(SKYBAKE_HAS_WINDOW)

#include "skybake/error.h"
#include "skybake/render.h"
#include "skybake/viewer.h"

namespace skybake {

namespace {
[[noreturn]] void no_window() {
    throw Error("this build has no window (GLFW or Dear ImGui was not found when it was configured; install "
                "libglfw3-dev and libimgui-dev and configure again); render headless with --screenshot",
                "display");
}
} // namespace

bool viewer_window_available() {
    return false;
}

void run_model_viewer(const ViewerModel&, const ModelViewerOptions&) {
    no_window();
}

void run_planet_viewer(const SkyModel&, const NeuralSky*, const ViewerOptions&) {
    no_window();
}

} // namespace skybake

#endif // !SKYBAKE_HAS_WINDOW
