// The OpenGL layer on the headless EGL context (Mesa llvmpipe is enough):
// the network's GLSL from the exporter, weights in a uniform block, evaluated
// on 10,000 inputs into an RGBA32F target, against the C++ forward pass of
// neural/mlp_hd.h; and the error paths (no EGL platform, a shader that does
// not compile).
#include <cmath>
#include <cstdlib>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "neural/error_bound_test_util.h"
#include "neural/device.h"
#include "neural/mlp_hd.h"
#include "gl/gl.h"
#include "skybake/error.h"
#include "skybake/neural.h"

namespace skybake::render {
namespace {

using namespace skybake::gl;

// A network with random weights of the seed's size or larger: the test is
// about the arithmetic, not about the sky.
NeuralSky random_net(const std::string& topology, std::uint64_t seed) {
    NeuralSky net;
    net.topology = parse_topology(topology);
    net.encoding.brightness = BrightnessEncoding::Log;
    net.encoding.max_n = 0.37;
    net.atmosphere = atmosphere_preset("paper");
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> n(0.0f, 0.6f);
    net.weights.resize(std::size_t(net.topology.weight_count()));
    for (float& w : net.weights)
        w = n(rng);
    return net;
}

constexpr const char* kVs = "#version 330 core\n"
                            "void main() {\n"
                            "    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n"
                            "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
                            "}\n";

constexpr const char* kFsMain = "uniform sampler2D u_in;\n"
                                "out vec4 o;\n"
                                "void main() {\n"
                                "    vec4 x = texelFetch(u_in, ivec2(gl_FragCoord.xy), 0);\n"
                                "    o = vec4(skybake_sky(x.x, x.y, x.z, x.w), 1.0);\n"
                                "}\n";

// GLSL ES 3.00 (WebGL 2): the same, in an OpenGL ES 3.0 context, with a
// fragment shader whose default float precision is mediump (the exported
// function computes in highp regardless).
constexpr const char* kVsEs = "#version 300 es\n"
                              "void main() {\n"
                              "    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n"
                              "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
                              "}\n";
constexpr const char* kFsEsHead = "#version 300 es\nprecision mediump float;\n";
constexpr const char* kFsEsMain = "uniform highp sampler2D u_in;\n"
                                  "out highp vec4 o;\n"
                                  "void main() {\n"
                                  "    highp vec4 x = texelFetch(u_in, ivec2(gl_FragCoord.xy), 0);\n"
                                  "    o = vec4(skybake_sky(x.x, x.y, x.z, x.w), 1.0);\n"
                                  "}\n";

// Worst relative RGB error |ΔI|/|I| of the GLSL (or GLSL ES) network over 100x100 inputs.
double glsl_network_error(const NeuralSky& net, int* compared, ExportLanguage lang = ExportLanguage::Glsl) {
    const bool es = lang == ExportLanguage::GlslEs;
    auto ctx = create_headless_context(es ? GlApi::Es3 : GlApi::Desktop);
    const int W = 100, H = 100;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), d(0.0f, 1.0f);
    std::vector<float> in(std::size_t(W * H * 4));
    for (std::size_t i = 0; i < in.size(); i += 4) {
        in[i] = u(rng);
        in[i + 1] = u(rng);
        in[i + 2] = u(rng);
        in[i + 3] = std::max(d(rng), 1e-3f);
    }
    Texture tex = make_texture();
    glBindTexture(GL_TEXTURE_2D, tex.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, W, H, 0, GL_RGBA, GL_FLOAT, in.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    ShaderExportOptions eo;
    eo.uniform_block = true;
    const std::string fn = export_neural_sky(net, lang, eo);
    Program p = es ? link_program("network test (GLSL ES)", ShaderSource{{kVsEs}}, ShaderSource{{kFsEsHead, fn, kFsEsMain}})
                   : link_program("network test", ShaderSource{{kVs}}, ShaderSource{{"#version 330 core\n", fn, kFsMain}});
    const std::vector<float> data = neural_sky_uniform_data(net);
    Buffer ubo = make_buffer();
    glBindBuffer(GL_UNIFORM_BUFFER, ubo.get());
    glBufferData(GL_UNIFORM_BUFFER, GLsizeiptr(data.size() * 4), data.data(), GL_STATIC_DRAW);
    glUniformBlockBinding(p.get(), glGetUniformBlockIndex(p.get(), "SkybakeSkyWeights"), 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, ubo.get());
    RenderTarget target(W, H);
    target.bind();
    glUseProgram(p.get());
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tex.get()); // after the target, which binds its own texture
    glUniform1i(glGetUniformLocation(p.get(), "u_in"), 0);
    VertexArray vao = make_vertex_array();
    glBindVertexArray(vao.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    const std::vector<float> out = target.read_rgba();
    check_gl("network test");

    const neural::MlpHD hd = neural::make_mlp_hd(net);
    double worst = 0.0;
    *compared = 0;
    for (int i = 0; i < W * H; ++i) {
        const float* x = in.data() + std::size_t(i) * 4;
        // Residual outputs follow the ray's geometry (its length, the planet's
        // shadow on it), which only a valid triple of cosines has; and below
        // 1e-6 of max N (deep twilight, 15 stops under the brightest sky) they
        // carry GLSL's exp tolerance, (3 + 2|x|) ulps, on arguments of tens.
        if (hd.output_kind == neural::kOutputsResidual && cosine_triple_determinant(x[0], x[1], x[2]) < 0.0)
            continue;
        const glm::vec3 ref = neural::neural_sky(hd, x[0], x[1], x[2], x[3]);
        if (hd.output_kind == neural::kOutputsResidual && glm::length(ref) < 1e-6f * hd.max_n)
            continue;
        const glm::vec3 got(out[std::size_t(i) * 4], out[std::size_t(i) * 4 + 1], out[std::size_t(i) * 4 + 2]);
        const double n = glm::length(glm::dvec3(ref));
        if (n == 0.0) {
            EXPECT_EQ(glm::length(got), 0.0f) << "night sample " << i;
            continue;
        }
        const double e = glm::length(glm::dvec3(got) - glm::dvec3(ref)) / n;
        if (e > worst && std::getenv("SKYBAKE_TEST_VERBOSE"))
            std::printf("sample %d (%.9g %.9g %.9g %.9g): ref %g %g %g got %g %g %g\n", i, x[0], x[1], x[2], x[3], ref.x,
                        ref.y, ref.z, got.x, got.y, got.z);
        worst = std::max(worst, e);
        ++*compared;
    }
    return worst;
}

TEST(GlNetwork, SeedTopologyMatchesTheCppForwardPass) {
    int compared = 0;
    const double err = glsl_network_error(random_net("paper", 5), &compared);
    EXPECT_GT(compared, 5000);
    EXPECT_LT(err, 1e-5) << "worst relative RGB error over " << compared << " inputs";
    RecordProperty("max_relative_error", std::to_string(err));
    std::printf("GLSL network (paper, uniform block) vs mlp_hd.h: max relative error %.3g over %d inputs\n", err,
                compared);
}

TEST(GlNetwork, WiderSharedTopologyMatchesToo) {
    int compared = 0;
    const double err = glsl_network_error(random_net("shared:16x16", 6), &compared);
    EXPECT_GT(compared, 5000);
    EXPECT_LT(err, 1e-5);
    std::printf("GLSL network (shared:16x16) vs mlp_hd.h: max relative error %.3g over %d inputs\n", err, compared);
}

// A random shared:12x8 network with the given encodings and moderate
// weights: the tests compare arithmetic, not saturated sigmoids.
NeuralSky encoded_network(InputEncoding inputs, OutputEncoding outputs, bool multiple = false) {
    NeuralSky net =
        neural_test::with_encoding(neural_test::random_network("shared:12x8", 7), inputs, outputs, 8, multiple);
    for (float& w : net.weights)
        w *= 0.5f;
    return net;
}

// `sky export --format glsl-es` (WebGL 2) in an OpenGL ES 3.0 context, every
// encoding: the same arithmetic as the library.
TEST(GlNetwork, GlslEsMatchesTheCppForwardPassInAnEsContext) {
    for (InputEncoding inputs : {InputEncoding::Seed, InputEncoding::Horizon})
        for (OutputEncoding outputs :
             {OutputEncoding::Radiance, OutputEncoding::PhaseFactored, OutputEncoding::Residual}) {
            const NeuralSky net = encoded_network(inputs, outputs);
            int compared = 0;
            const double err = glsl_network_error(net, &compared, ExportLanguage::GlslEs);
            SCOPED_TRACE(std::string(input_encoding_name(inputs)) + " / " + output_encoding_name(outputs));
            EXPECT_GT(compared, 3000);
            EXPECT_LT(err, 1e-5);
            std::printf("GLSL ES network (%s inputs, %s outputs) vs mlp_hd.h: max relative error %.3g over %d inputs\n",
                        input_encoding_name(inputs), output_encoding_name(outputs), err, compared);
        }
    int compared = 0;
    const double err = glsl_network_error(random_net("paper", 5), &compared, ExportLanguage::GlslEs);
    EXPECT_LT(err, 1e-5);
    auto ctx = create_headless_context(GlApi::Es3);
    EXPECT_TRUE(ctx->is_es());
    EXPECT_GE(ctx->major_version(), 3);
}

// Horizon inputs and phase-factored outputs: the encoding constants after the
// weights in the uniform block (atmosphere radii, phase terms) reach the GLSL.
TEST(GlNetwork, EveryEncodingMatchesTheCppForwardPass) {
    for (InputEncoding inputs : {InputEncoding::Seed, InputEncoding::Horizon})
        for (OutputEncoding outputs :
             {OutputEncoding::Radiance, OutputEncoding::PhaseFactored, OutputEncoding::Residual}) {
            const NeuralSky net = encoded_network(inputs, outputs);
            int compared = 0;
            const double err = glsl_network_error(net, &compared);
            SCOPED_TRACE(std::string(input_encoding_name(inputs)) + " / " + output_encoding_name(outputs));
            EXPECT_GT(compared, 3000);
            EXPECT_LT(err, 1e-5);
            std::printf("GLSL network (%s inputs, %s outputs) vs mlp_hd.h: max relative error %.3g over %d inputs\n",
                        input_encoding_name(inputs), output_encoding_name(outputs), err, compared);
        }
    // Residual outputs of a sky with multiple scattering: the multiply
    // scattered light's term and its constants in the uniform block, in
    // desktop GLSL and in GLSL ES.
    for (ExportLanguage lang : {ExportLanguage::Glsl, ExportLanguage::GlslEs})
        for (bool march : {false, true}) { // log-encoded, or a correction of the isotropic march (ψ in the block)
            NeuralSky net = encoded_network(InputEncoding::Horizon, OutputEncoding::Residual, true);
            if (march)
                net = neural_test::with_marched_multiple(std::move(net));
            int compared = 0;
            const double err = glsl_network_error(net, &compared, lang);
            EXPECT_GT(compared, 3000);
            EXPECT_LT(err, 1e-5) << (march ? "marched" : "log-encoded");
            std::printf("%s network (residual outputs, multiple scattering%s) vs mlp_hd.h: max relative error %.3g "
                        "over %d inputs\n",
                        lang == ExportLanguage::Glsl ? "GLSL" : "GLSL ES", march ? ", marched" : "", err, compared);
        }
    // An aerosol family: its fifth input and the march's scaled aerosol, the
    // amount read from the uniform block (the renderers' path).
    for (ExportLanguage lang : {ExportLanguage::Glsl, ExportLanguage::GlslEs}) {
        NeuralSky net = neural_test::with_family(encoded_network(InputEncoding::Horizon, OutputEncoding::Residual), 1.0,
                                                 32.0, 6.5, 12);
        for (float& w : net.weights)
            w *= 0.5f;
        int compared = 0;
        const double err = glsl_network_error(net, &compared, lang);
        EXPECT_GT(compared, 3000);
        EXPECT_LT(err, 1e-5);
        std::printf("%s network (residual outputs, aerosol family at 6.5) vs mlp_hd.h: max relative error %.3g over "
                    "%d inputs\n",
                    lang == ExportLanguage::Glsl ? "GLSL" : "GLSL ES", err, compared);
    }
}

// The uniform-block source depends on the topology and the encoding only.
TEST(GlNetwork, UniformBlockSourceDoesNotDependOnTheWeights) {
    ShaderExportOptions eo;
    eo.uniform_block = true;
    NeuralSky other = random_net("paper", 2);
    other.atmosphere = atmosphere_preset("earth");
    other.encoding.max_n = 0.05;
    EXPECT_EQ(export_neural_sky(random_net("paper", 1), ExportLanguage::Glsl, eo),
              export_neural_sky(other, ExportLanguage::Glsl, eo));
    EXPECT_NE(export_neural_sky(random_net("paper", 1), ExportLanguage::Glsl),
              export_neural_sky(random_net("paper", 2), ExportLanguage::Glsl));
    const std::vector<float> data = neural_sky_uniform_data(random_net("paper", 1));
    EXPECT_EQ(data.size(), 328u); // 324 weights, max N, log range, padded to vec4s
}

TEST(GlContext, ReportsDesktopGl33OrNewer) {
    auto ctx = create_headless_context();
    EXPECT_GE(ctx->major_version() * 10 + ctx->minor_version(), 33) << ctx->description();
}

// Contexts share the process's EGL display: releasing one must leave another
// working (a context that terminated the display took every other one with
// it), and releasing one that is not current leaves the current one current.
TEST(GlContext, ReleasingOneContextLeavesAnotherWorking) {
    const auto clear_and_read = [](float red) {
        RenderTarget target(2, 2);
        target.bind();
        glClearColor(red, 0.5f, 0.75f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        check_gl("clear");
        const std::vector<float> rgba = target.read_rgba();
        return rgba.size() == 16 && rgba[1] == 0.5f && rgba[2] == 0.75f ? rgba[0] : -1.0f;
    };
    auto first = create_headless_context();
    auto second = create_headless_context();
    first.reset(); // the current one was the second
    EXPECT_EQ(clear_and_read(0.25f), 0.25f);
    auto third = create_headless_context();
    second->make_current();
    third.reset(); // not current: the second stays current
    EXPECT_EQ(clear_and_read(0.125f), 0.125f);
    second.reset();
    auto fourth = create_headless_context(); // and a new one still comes up
    EXPECT_EQ(clear_and_read(0.375f), 0.375f);
}

TEST(GlContext, NoPlatformIsOneClearError) {
    setenv("SKYBAKE_EGL_PLATFORM", "none", 1);
    try {
        create_headless_context();
        unsetenv("SKYBAKE_EGL_PLATFORM");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        unsetenv("SKYBAKE_EGL_PLATFORM");
        EXPECT_NE(e.message().find("no headless OpenGL"), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
        EXPECT_EQ(e.where(), "OpenGL");
    }
}

TEST(GlContext, ShaderCompileErrorNamesTheStageAndTheFirstLogLine) {
    auto ctx = create_headless_context();
    try {
        link_program("broken", ShaderSource{{kVs}},
                     ShaderSource{{"#version 330 core\nout vec4 o;\nvoid main() { o = undefined_thing; }\n"}});
        FAIL() << "expected an error";
    } catch (const Error& e) {
        const std::string m = e.message();
        EXPECT_EQ(m.rfind("fragment shader does not compile: ", 0), 0u) << m;
        EXPECT_NE(m.find("undefined_thing"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos);
        EXPECT_EQ(e.where(), "broken shader");
    }
}

} // namespace
} // namespace skybake::render
