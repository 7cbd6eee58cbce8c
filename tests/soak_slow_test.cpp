// Soak: the library called thousands of times in one process, as the Python
// module and the Blender add-on will call it. Each cycle loads a mesh, bakes
// it with Embree, writes and reloads it, builds a sky model, renders a small
// sky, evaluates a network, and creates and destroys a headless GL context
// (compiling a program and drawing into a framebuffer with it). Resident
// memory after the last cycle must stay within 5% of what it was after the
// first tenth; in the sanitizer build (fewer cycles) LeakSanitizer checks that
// nothing leaks at exit. That build leaves the GL cycle out: Mesa is not
// built with the sanitizers and keeps allocations of its own for the process.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "cli_runner.h"
#include "gl/gl.h"
#include "skybake/bake.h"
#include "skybake/error.h"
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

#if !defined(SKYBAKE_ASAN)
constexpr bool kGlCycle = true;
#else
constexpr bool kGlCycle = false;
#endif

// One GL cycle: a context, a program, a 4×4 target filled by a full-screen
// triangle with a colour that depends on the cycle, read back; returns the
// red value read, which must be the one drawn.
float gl_cycle(int cycle) {
    using namespace skybake;
    const std::unique_ptr<gl::GlContext> context = gl::create_headless_context();
    const gl::Program program = gl::link_program(
        "soak",
        gl::ShaderSource{{"#version 330 core\n", "void main() { vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);"
                                                 " gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0); }\n"}},
        gl::ShaderSource{{"#version 330 core\n", "uniform float u_red; out vec4 colour;"
                                                 " void main() { colour = vec4(u_red, 0.25, 0.5, 1.0); }\n"}});
    gl::RenderTarget target(4, 4);
    target.bind();
    glViewport(0, 0, 4, 4);
    const gl::VertexArray vao = gl::make_vertex_array();
    glBindVertexArray(vao.get());
    glUseProgram(program.get());
    glUniform1f(glGetUniformLocation(program.get(), "u_red"), float(cycle % 8) / 8.0f);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    gl::check_gl("soak draw");
    return target.read_rgba()[4 * 5]; // pixel (1, 1)
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
    std::string gl_missing;
    if (kGlCycle) {
        try {
            (void)gl::create_headless_context();
        } catch (const Error& e) {
            gl_missing = e.what(); // a machine without EGL: the rest still soaks
        }
    }
    const bool with_gl = kGlCycle && gl_missing.empty();
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

        if (with_gl) {
            const float red = gl_cycle(c);
            ASSERT_EQ(red, float(c % 8) / 8.0f) << "cycle " << c; // exact in 8 bits and in float
            checksum += red;
        }

        if (c == cycles / 10)
            after_tenth = resident_mib();
    }
    const double at_end = resident_mib();
    if (kGlCycle && !with_gl)
        std::printf("soak: no GL context (%s); the GL cycle is left out\n", gl_missing.c_str());
    std::printf("soak: %d cycles%s; resident memory %.1f MiB after cycle %d, %.1f MiB after cycle %d (%+.2f%%); "
                "checksum %.6g\n",
                cycles, with_gl ? " with GL" : "", after_tenth, cycles / 10, at_end, cycles,
                100.0 * (at_end / after_tenth - 1.0), checksum);
#if defined(SKYBAKE_ASAN)
    // AddressSanitizer keeps freed memory in quarantine (256 MiB by default):
    // resident memory grows by design there, and LeakSanitizer is the check.
    (void)after_tenth;
#else
    EXPECT_LE(at_end, 1.05 * after_tenth);
#endif
    EXPECT_TRUE(std::isfinite(checksum));
}
