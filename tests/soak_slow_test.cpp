// Soak: the library called thousands of times in one process, as the Python
// module and the Blender add-on will call it. Each cycle loads a mesh, bakes
// it with Embree, writes and reloads it, builds a sky model, renders a small
// sky and evaluates a network. Resident memory after the last cycle must stay
// within 5% of what it was after the first tenth; in the sanitizer build
// (fewer cycles) LeakSanitizer checks that nothing leaks at exit.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "cli_runner.h"
#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/neural.h"
#include "skybake/sky.h"
#include "skybake/sphere.h"

#ifndef SKYBAKE_SOAK_CYCLES
#define SKYBAKE_SOAK_CYCLES 1000
#endif

namespace {

double resident_mib() {
    std::ifstream statm("/proc/self/statm");
    long pages = 0, resident = 0;
    statm >> pages >> resident;
    return double(resident) * double(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

} // namespace

TEST(Soak, MemoryStaysFlatOverManyCycles) {
    using namespace skybake;
    const int cycles = SKYBAKE_SOAK_CYCLES;
    const std::string dir = test::temp_dir("soak");
    const std::string mesh_path = dir + "/city.glb", out_path = dir + "/city_ao.glb";
    save_mesh(mesh_path, generate_mesh({ProceduralKind::City, 1500, 1}));
    const SphereRule rule = parse_rule("lebedev:26");

    NeuralTrainOptions t;
    t.samples = 400;
    t.heldout_samples = 50;
    t.adam_epochs = 1;
    t.batch = 200;
    t.lm_iterations = 0;
    t.progress = false;
    SkyModelOptions small;
    small.tables = {32, 16};
    const NeuralSky net = train_neural_sky(SkyModel(atmosphere_preset("paper-dense"), small), t);
    const std::vector<SkySample> samples = draw_sky_samples(256, 3);
    std::vector<glm::vec3> radiance(samples.size());

    SkyRenderSettings view;
    view.width = view.height = 16;
    double after_tenth = 0.0, checksum = 0.0;
    for (int c = 1; c <= cycles; ++c) {
        Mesh m = load_mesh(mesh_path);
        bake_ambient_occlusion(m, rule, "embree");
        save_mesh(out_path, m);
        const Mesh back = load_mesh(out_path);
        ASSERT_TRUE(back.find_attribute("ao")) << "cycle " << c;
        checksum += back.find_attribute("ao")->values[0];

        const SkyModel model(atmosphere_preset(c % 2 ? "earth" : "paper"), small);
        const Image sky = render_sky(model, view);
        checksum += sky.rgb[sky.rgb.size() / 2];

        evaluate_neural_sky(net, samples, radiance);
        checksum += radiance[7].x;

        if (c == cycles / 10)
            after_tenth = resident_mib();
    }
    const double at_end = resident_mib();
    std::printf("soak: %d cycles; resident memory %.1f MiB after cycle %d, %.1f MiB after cycle %d (%+.2f%%); "
                "checksum %.6g\n",
                cycles, after_tenth, cycles / 10, at_end, cycles, 100.0 * (at_end / after_tenth - 1.0), checksum);
#if defined(SKYBAKE_ASAN)
    // AddressSanitizer keeps freed memory in quarantine (256 MiB by default):
    // resident memory grows by design there, and LeakSanitizer is the check.
    (void)after_tenth;
#else
    EXPECT_LE(at_end, 1.05 * after_tenth);
#endif
    EXPECT_TRUE(std::isfinite(checksum));
}
