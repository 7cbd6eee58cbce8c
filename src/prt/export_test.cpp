// GLSL export of the relighting functions (skybake/prt.h, [SECTION] Shader
// export): compiles with glslangValidator in vertex and fragment shaders, and
// carries the Phong rule's points and weights.
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

bool have(const char* tool) {
    return std::system(fmt::format("command -v {} >/dev/null 2>&1", tool).c_str()) == 0;
}

NeuralSky small_net() {
    NeuralSky net;
    net.topology = parse_topology("shared:8x8");
    net.encoding.max_n = 0.15;
    net.atmosphere = atmosphere_preset("earth");
    std::uint64_t state = 99;
    net.weights.resize(std::size_t(net.topology.weight_count()));
    for (float& w : net.weights) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        w = float(double(state >> 11) * 0x1.0p-53 * 2.0 - 1.0);
    }
    return net;
}

TEST(PrtExport, GlslCompiles) {
    if (!have("glslangValidator"))
        GTEST_SKIP() << "glslangValidator not installed (Debian package glslang-tools)";
    const fs::path dir = fs::temp_directory_path() / fmt::format("skybake_prt_export_{}", ::getpid());
    fs::create_directories(dir);
    const SphereRule phong = phong_rule(16.0, 3);
    const NeuralSky net = small_net();
    for (int channels : {1, 3}) {
        PrtShaderOptions o;
        o.phong = &phong;
        o.network = &net;
        const std::string fn = export_prt_glsl(3, channels, o);
        const int m = (channels * 16 + 3) / 4;
        std::string attrs;
        for (int i = 0; i < m; ++i)
            attrs += fmt::format("layout(location = {}) in vec4 _PRT_{};\n", i + 1, i);
        std::string gather = fmt::format("    vec4 t[{}];\n", m);
        for (int i = 0; i < m; ++i)
            gather += fmt::format("    t[{}] = _PRT_{};\n", i, i);
        const std::string vert = "#version 330 core\n" + fn + attrs +
                                 "uniform vec3 light[16];\nlayout(location = 0) in vec3 pos;\nout vec3 colour;\n"
                                 "void main() {\n" +
                                 gather +
                                 "    colour = skybake_prt_diffuse(t, light, vec3(0.8)) +\n"
                                 "             skybake_prt_glossy(vec3(0.0, 1.0, 0.0), normalize(pos), "
                                 "vec3(0.0, 0.6, 0.8), 1.0);\n"
                                 "    gl_Position = vec4(pos, 1.0);\n}\n";
        // A fragment shader calling both functions, under a default precision.
        const auto fragment = [m](const char* precision, const std::string& functions) {
            return std::string("#version 300 es\nprecision ") + precision + " float;\n" + functions +
                   "uniform vec3 light[16];\nuniform vec4 t[" + std::to_string(m) +
                   "];\nin vec3 nrm;\nout vec4 frag;\n"
                   "void main() { frag = vec4(skybake_prt_diffuse(t, light, vec3(0.5)) + "
                   "skybake_prt_glossy(normalize(nrm), vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), "
                   "0.5), 1.0); }\n";
        };
        const std::string frag = fragment("highp", fn);
        // GLSL ES 3.00 (WebGL 2) under a mediump default.
        o.es = true;
        const std::string es = export_prt_glsl(3, channels, o);
        o.es = false;
        EXPECT_NE(es.find("highp vec3 skybake_prt_diffuse("), std::string::npos);
        const std::string frag_es = fragment("mediump", es);
        for (const auto& [name, text] :
             {std::pair{"prt.vert", vert}, std::pair{"prt.frag", frag}, std::pair{"prt_es.frag", frag_es}}) {
            std::ofstream(dir / name) << text;
            const std::string cmd =
                fmt::format("glslangValidator {} > {} 2>&1", (dir / name).string(), (dir / "log.txt").string());
            const int rc = std::system(cmd.c_str());
            std::ifstream log(dir / "log.txt");
            EXPECT_EQ(rc, 0) << name << " channels " << channels << ": "
                             << std::string(std::istreambuf_iterator<char>(log), {});
        }
        // Every rule point's weight is in the text.
        EXPECT_NE(fn.find(fmt::format("{:.9g}", phong.weights[0])), std::string::npos);
    }
    fs::remove_all(dir);
}

TEST(PrtExport, BadOptions) {
    EXPECT_THROW(export_prt_glsl(9, 1), Error);
    EXPECT_THROW(export_prt_glsl(3, 2), Error);
    const SphereRule lebedev = parse_rule("lebedev:50");
    const NeuralSky net = small_net();
    PrtShaderOptions o;
    o.phong = &lebedev;
    o.network = &net;
    EXPECT_THROW(export_prt_glsl(3, 1, o), Error);
    o.network = nullptr;
    EXPECT_THROW(export_prt_glsl(3, 1, o), Error);
    EXPECT_NE(export_prt_glsl(2, 1).find("vec3 skybake_prt_diffuse(vec4 prt[3], vec3 light[9], vec3 albedo)"),
              std::string::npos);
}

TEST(PrtExport, RefusesNamesThatAreNotIdentifiers) {
    PrtShaderOptions o;
    for (const char* bad : {"x(); } evil {", "", "2d", "gl_prt", "a b", "a-b"}) {
        o.function_name = bad;
        try {
            (void)export_prt_glsl(3, 1, o);
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const Error& e) {
            EXPECT_EQ(e.where(), "name") << bad;
        }
    }
    o.function_name = "My_prt2";
    EXPECT_NE(export_prt_glsl(1, 1, o).find("vec3 My_prt2_diffuse("), std::string::npos);
}

} // namespace
} // namespace skybake
