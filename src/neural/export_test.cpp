// Tests of the shader/C export: the exported C and CUDA (compiled as C++)
// agree with the library's inference to 1e-6 relative; the GLSL compiles with
// glslangValidator in vertex and fragment shaders, the HLSL in its HLSL mode.
#include <algorithm>
#include <bit>
#include <cmath>
#include <regex>
#include <set>
#include <utility>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "neural/error_bound_test_util.h"
#include "skybake/error.h"
#include "skybake/neural.h"

using namespace skybake;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
    const fs::path p = fs::temp_directory_path() / fmt::format("skybake_export_test_{}_{}", name, ::getpid());
    fs::create_directories(p);
    return p;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

bool have(const char* tool) { return std::system(fmt::format("command -v {} >/dev/null 2>&1", tool).c_str()) == 0; }

// A small trained-looking network: random weights of realistic size.
NeuralSky make_net(const char* topology, BrightnessEncoding b) {
    NeuralSky net;
    net.topology = parse_topology(topology);
    net.encoding.brightness = b;
    net.encoding.max_n = 0.15;
    net.atmosphere = atmosphere_preset("earth");
    std::uint64_t state = 12345;
    net.weights.resize(std::size_t(net.topology.weight_count()));
    for (float& w : net.weights) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        w = float(double(state >> 11) * 0x1.0p-53 * 4.0 - 2.0);
    }
    return net;
}

// The encodings beyond the seed's, on the same topology.
struct Encoding {
    InputEncoding inputs;
    OutputEncoding outputs;
    const char* name;
    bool multiple = false; // residual outputs of a sky with multiple scattering
    bool march = false;    // its term a correction of the isotropic march
};
constexpr Encoding kNewEncodings[] = {
    {InputEncoding::Horizon, OutputEncoding::Radiance, "horizon/radiance"},
    {InputEncoding::Seed, OutputEncoding::PhaseFactored, "seed/phase-factored"},
    {InputEncoding::Horizon, OutputEncoding::PhaseFactored, "horizon/phase-factored"},
    {InputEncoding::Seed, OutputEncoding::Residual, "seed/residual"},
    {InputEncoding::Horizon, OutputEncoding::Residual, "horizon/residual"},
    {InputEncoding::Horizon, OutputEncoding::Residual, "horizon/residual, multiple scattering", true},
    {InputEncoding::Horizon, OutputEncoding::Residual, "horizon/residual, multiple scattering marched", true, true},
};

NeuralSky encoded(NeuralSky net, const Encoding& e) {
    net = neural_test::with_encoding(std::move(net), e.inputs, e.outputs, 7, e.multiple);
    return e.march ? neural_test::with_marched_multiple(std::move(net)) : net;
}

// Every network the tests below export: two topologies, both brightness codes
// of the seed's encoding, and each new encoding.
std::vector<std::pair<std::string, NeuralSky>> export_cases() {
    std::vector<std::pair<std::string, NeuralSky>> cases;
    for (const char* top : {"paper", "shared:16x8"}) {
        cases.emplace_back(fmt::format("{} log", top), make_net(top, BrightnessEncoding::Log));
        cases.emplace_back(fmt::format("{} linear", top), make_net(top, BrightnessEncoding::Linear));
        for (const Encoding& e : kNewEncodings)
            cases.emplace_back(fmt::format("{} {}", top, e.name), encoded(make_net(top, BrightnessEncoding::Log), e));
        // An aerosol family: a fifth argument, and the march's aerosol scaled by it.
        cases.emplace_back(
            fmt::format("{} horizon/residual, aerosol family at 3.7", top),
            neural_test::with_family(neural_test::with_encoding(make_net(top, BrightnessEncoding::Log),
                                                                InputEncoding::Horizon, OutputEncoding::Residual, 7),
                                     0.5, 16.0, 3.7, 9));
    }
    return cases;
}

// Reads samples, writes the export's RGB; ARGS is how the function is called.
const char* kDriver = R"(
#include <stdio.h>
int main(void) {
    float a, b, c, d, rgb[3];
    while (scanf("%f %f %f %f", &a, &b, &c, &d) == 4) {
        skybake_sky(ARGS, rgb);
        printf("%.9g %.9g %.9g\n", rgb[0], rgb[1], rgb[2]);
    }
    return 0;
}
)";

// The arguments of a call: an aerosol family's amount after the four.
std::string args(const NeuralSky& net, const std::string& four) {
    return net.encoding.has_family() ? fmt::format("{}, {:.9g}", four, net.aerosol) : four;
}

std::string driver(const NeuralSky& net) {
    std::string d = kDriver;
    const std::string args = net.encoding.has_family() ? fmt::format("a, b, c, d, {:.9g}f", net.aerosol) : "a, b, c, d";
    d.replace(d.find("ARGS"), 4, args);
    return d;
}

// Compiles the export with the system compiler and runs it on the samples.
std::vector<glm::vec3> run_exported(const NeuralSky& net, ExportLanguage lang, const std::vector<SkySample>& s,
                                    const fs::path& dir) {
    const bool c = lang == ExportLanguage::C;
    const fs::path src = dir / (c ? "sky.c" : "sky.cpp"), exe = dir / "sky", in = dir / "in.txt", out = dir / "out.txt";
    write(src, export_neural_sky(net, lang) + driver(net));
    std::ostringstream samples;
    for (const SkySample& x : s)
        samples << fmt::format("{:.9g} {:.9g} {:.9g} {:.9g}\n", x.cos_view_zenith, x.cos_view_sun, x.cos_sun_zenith,
                               x.density);
    write(in, samples.str());
    const std::string cmd =
        c ? fmt::format("cc -std=c99 -O2 -Wall -Werror -o {} {} -lm", exe.string(), src.string())
          : fmt::format("c++ -std=c++17 -O2 -Wall -Werror -o {} {} -lm", exe.string(), src.string());
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(std::system(fmt::format("{} < {} > {}", exe.string(), in.string(), out.string()).c_str()), 0);
    std::ifstream f(out);
    std::vector<glm::vec3> r;
    glm::vec3 v;
    while (f >> v.x >> v.y >> v.z)
        r.push_back(v);
    return r;
}

double relative(const glm::vec3& a, const glm::vec3& ref) {
    const double d = glm::length(glm::dvec3(a) - glm::dvec3(ref)), n = glm::length(glm::dvec3(ref));
    return n > 0.0 ? d / n : d;
}

} // namespace

TEST(NeuralExport, CAndCudaAgreeWithTheLibrary) {
    if (!have("cc") || !have("c++"))
        GTEST_SKIP() << "no system C/C++ compiler";
    const std::vector<SkySample> s = draw_sky_samples(2000, 77);
    for (const auto& [name, net] : export_cases()) {
        const char* top = name.c_str();
        {
            std::vector<glm::vec3> batch(s.size());
            evaluate_neural_sky(net, s, batch);
            for (ExportLanguage lang : {ExportLanguage::C, ExportLanguage::Cuda}) {
                const std::vector<glm::vec3> got = run_exported(net, lang, s, scratch("c"));
                ASSERT_EQ(got.size(), s.size());
                double worst_scalar = 0.0, worst_batch = 0.0;
                int lit = 0;
                for (std::size_t i = 0; i < s.size(); ++i) {
                    const glm::vec3 scalar = neural_sky_radiance(net, s[i]);
                    lit += glm::length(scalar) > 0.0f;
                    if (relative(got[i], scalar) > 1e-3 && std::getenv("SKYBAKE_TEST_VERBOSE"))
                        std::printf("sample %zu (%.9g %.9g %.9g %.9g): scalar %g %g %g, export %g %g %g\n", i,
                                    s[i].cos_view_zenith, s[i].cos_view_sun, s[i].cos_sun_zenith, s[i].density,
                                    scalar.x, scalar.y, scalar.z, got[i].x, got[i].y, got[i].z);
                    worst_scalar = std::max(worst_scalar, relative(got[i], scalar));
                    worst_batch = std::max(worst_batch, relative(got[i], batch[i]));
                }
                EXPECT_GT(lit, 100);
                std::printf("%s, %s: worst relative difference %.3g (scalar), %.3g (batch)\n", top,
                            lang == ExportLanguage::C ? "C" : "CUDA as C++", worst_scalar, worst_batch);
                // The export repeats the scalar pass operation for operation.
                EXPECT_LE(worst_scalar, 1e-6) << top << " against the scalar forward pass";
                // The batch pass uses Eigen's vectorised exp and its own summation
                // order: float rounding (~1e-7 in the outputs) that the log
                // brightness decoding multiplies by log_range (13.8), or the
                // multiple-scattering term's by 27.6 (kMultipleLogRange).
                EXPECT_LE(worst_batch, net.encoding.multiple ? 1e-5 : 5e-6) << top << " against the batch inference";
            }
        }
    }
}

TEST(NeuralExport, GlslCompilesInVertexAndFragmentShaders) {
    if (!have("glslangValidator"))
        GTEST_SKIP() << "glslangValidator not installed (Debian package glslang-tools)";
    const fs::path dir = scratch("glsl");
    std::vector<std::pair<std::string, NeuralSky>> nets{{"paper", make_net("paper", BrightnessEncoding::Log)},
                                                        {"independent:16x16",
                                                         make_net("independent:16x16", BrightnessEncoding::Log)}};
    for (const Encoding& e : kNewEncodings)
        nets.emplace_back(e.name, encoded(make_net("paper", BrightnessEncoding::Log), e));
    nets.emplace_back("aerosol family",
                      neural_test::with_family(neural_test::with_encoding(make_net("paper", BrightnessEncoding::Log),
                                                                          InputEncoding::Horizon,
                                                                          OutputEncoding::Residual, 3),
                                               1.0, 32.0, 2.5, 4));
    for (const auto& [top, net] : nets) {
        const std::string fn = export_neural_sky(net, ExportLanguage::Glsl);
        const std::string attr = args(net, "attr.x, attr.y, attr.z, attr.w");
        const std::string dirs = args(net, "dirs.x, dirs.y, dirs.z, dirs.w");
        write(dir / "sky.vert", "#version 330 core\n" + fn +
                                    "layout(location = 0) in vec4 attr;\nout vec3 colour;\n"
                                    "void main() {\n    colour = skybake_sky(" + attr + ");\n"
                                    "    gl_Position = vec4(attr.xyz, 1.0);\n}\n");
        write(dir / "sky.frag", "#version 300 es\nprecision highp float;\n" + fn +
                                    "in vec4 dirs;\nout vec4 frag;\n"
                                    "void main() { frag = vec4(skybake_sky(" + dirs + "), 1.0); }\n");
        // GLSL ES 3.00 (WebGL 2) under a mediump default, in both stages.
        const std::string es = export_neural_sky(net, ExportLanguage::GlslEs);
        write(dir / "sky_es.frag", "#version 300 es\nprecision mediump float;\n" + es +
                                       "in vec4 dirs;\nout vec4 frag;\n"
                                       "void main() { frag = vec4(skybake_sky(" + dirs + "), 1.0); }\n");
        write(dir / "sky_es.vert", "#version 300 es\n" + es +
                                       "in vec4 attr;\nout vec3 colour;\n"
                                       "void main() {\n    colour = skybake_sky(" + attr + ");\n"
                                       "    gl_Position = vec4(attr.xyz, 1.0);\n}\n");
        for (const char* stage : {"sky.vert", "sky.frag", "sky_es.vert", "sky_es.frag"}) {
            const std::string cmd = fmt::format("glslangValidator {} > {} 2>&1", (dir / stage).string(),
                                                (dir / "log.txt").string());
            const int rc = std::system(cmd.c_str());
            std::ifstream log_file(dir / "log.txt"); // opened after the run, so that it holds this run's log
            EXPECT_EQ(rc, 0) << top << " " << stage << ": "
                             << std::string(std::istreambuf_iterator<char>(log_file), {});
        }
    }
}

TEST(NeuralExport, HlslCompiles) {
    if (!have("glslangValidator"))
        GTEST_SKIP() << "glslangValidator not installed (Debian package glslang-tools)";
    const fs::path dir = scratch("hlsl");
    for (const auto& [name, net] : export_cases()) {
        const std::string fn = export_neural_sky(net, ExportLanguage::Hlsl);
        write(dir / "sky.hlsl", fn + "float4 main(float4 d : TEXCOORD0) : SV_Target {\n" +
                                    fmt::format("    return float4(skybake_sky({}), 1.0f);\n}}\n",
                                                args(net, "d.x, d.y, d.z, d.w")));
        const std::string cmd = fmt::format("glslangValidator -D -V -e main -S frag -o {} {} > {} 2>&1",
                                            (dir / "sky.spv").string(), (dir / "sky.hlsl").string(),
                                            (dir / "log.txt").string());
        const int rc = std::system(cmd.c_str());
        std::ifstream log_file(dir / "log.txt");
        EXPECT_EQ(rc, 0) << name << ": " << std::string(std::istreambuf_iterator<char>(log_file), {});
    }
}

namespace {

// Every float literal of an exported source, in order (a literal always has a
// '.' or an exponent; identifiers such as s0_1_2 and indices are skipped).
std::vector<float> float_literals(const std::string& src) {
    static const std::regex re(R"(([0-9]+\.[0-9]*(?:e[-+]?[0-9]+)?|[0-9]+e[-+]?[0-9]+)f?)");
    std::vector<float> out;
    for (auto it = std::sregex_iterator(src.begin(), src.end(), re); it != std::sregex_iterator(); ++it) {
        const auto pos = std::size_t(it->position(0));
        if (pos > 0) {
            const unsigned char c = static_cast<unsigned char>(src[pos - 1]);
            if (std::isalnum(c) || c == '_' || c == '.')
                continue;
        }
        out.push_back(std::strtof(it->str(1).c_str(), nullptr));
    }
    return out;
}

// The literals of the layers, in order, and the set of the decoding's constants.
std::pair<std::vector<float>, std::set<float>> split_at_decoding(const std::string& src) {
    const std::size_t cut = src.find("// decoding");
    EXPECT_NE(cut, std::string::npos);
    const std::vector<float> tail = float_literals(src.substr(cut));
    return {float_literals(src.substr(0, cut)), std::set<float>(tail.begin(), tail.end())};
}

} // namespace

TEST(NeuralExport, ShaderLiteralsEqualTheCExports) {
    // The C export is checked against the library to 1e-6 above; the GLSL and
    // HLSL only compile. Their numbers must be the C export's, bit for bit and
    // in the same order, so a rounding or a dropped weight in one dialect fails.
    for (const auto& [name, net] : export_cases())
        {
            const char* top = name.c_str();
            const std::vector<float> c = float_literals(export_neural_sky(net, ExportLanguage::C));
            ASSERT_GE(c.size(), std::size_t(net.topology.weight_count())) << top;
            // The weights appear among them, each as the float it is.
            std::vector<float> sorted_c = c, sorted_w = net.weights;
            for (float& w : sorted_w)
                w = std::abs(w);
            std::sort(sorted_c.begin(), sorted_c.end());
            std::sort(sorted_w.begin(), sorted_w.end());
            EXPECT_TRUE(std::includes(sorted_c.begin(), sorted_c.end(), sorted_w.begin(), sorted_w.end())) << top;
            const auto [c_net, c_decode] = split_at_decoding(export_neural_sky(net, ExportLanguage::C));
            for (ExportLanguage lang :
                 {ExportLanguage::Glsl, ExportLanguage::GlslEs, ExportLanguage::Hlsl, ExportLanguage::Cuda}) {
                const auto [o_net, o_decode] = split_at_decoding(export_neural_sky(net, lang));
                // The layers: the same literals in the same order.
                ASSERT_EQ(o_net.size(), c_net.size()) << top << " language " << int(lang);
                for (std::size_t i = 0; i < c_net.size(); ++i)
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(o_net[i]), std::bit_cast<std::uint32_t>(c_net[i]))
                        << top << " language " << int(lang) << " literal " << i;
                // The decoding: a vector max in shaders, per-channel tests in C,
                // so the same constants, not the same count.
                EXPECT_EQ(o_decode, c_decode) << top << " language " << int(lang);
            }
        }
}

TEST(NeuralExport, RejectsBadNames) {
    const NeuralSky net = make_net("paper", BrightnessEncoding::Log);
    EXPECT_THROW(export_neural_sky(net, ExportLanguage::Glsl, "9sky"), Error);
    EXPECT_THROW(export_neural_sky(net, ExportLanguage::Glsl, "gl_sky"), Error);
    EXPECT_THROW(export_neural_sky(net, ExportLanguage::C, "sky-colour"), Error);
    EXPECT_THROW(parse_export_language("metal"), Error);
    EXPECT_NE(export_neural_sky(net, ExportLanguage::Glsl, "my_sky").find("vec3 my_sky("), std::string::npos);
}
