// GLSL relighting functions for engines: diffuse PRT (Sloan, Kautz & Snyder
// 2002: one dot product per vertex) and DPRT glossy with the sky network
// (seed 002's weighted Phong designs; seed 000's network). See skybake/prt.h,
// [SECTION] Shader export.
#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {

namespace {
// A GLSL float literal: "1" would be an int, which GLSL ES does not convert.
std::string glsl_float(double x) {
    std::string t = fmt::format("{:.9g}", x);
    if (t.find_first_of(".en") == std::string::npos)
        t += ".0";
    return t;
}
} // namespace

std::string export_prt_glsl(int order, int channels, const PrtShaderOptions& o) {
    if (order < 0 || order > kPrtMaxOrder)
        throw Error(fmt::format("SH order must be 0 to {}; got {}", kPrtMaxOrder, order), "order");
    if (channels != 1 && channels != 3)
        throw Error(fmt::format("a transfer has 1 or 3 channels; got {}", channels), "channels");
    if ((o.phong != nullptr) != (o.network != nullptr))
        throw Error("the glossy function needs both a Phong rule and a network", "phong");
    if (o.phong && o.phong->kind != RuleKind::Phong)
        throw Error(fmt::format("'{}' is not a Phong rule", o.phong->spec), "phong");
    const std::string& name = o.function_name;
    if (!valid_shader_identifier(name))
        throw Error(fmt::format("'{}' is not a valid function name prefix (letters, digits and _, not starting with "
                                "a digit or gl_)",
                                name),
                    "name");
    const int nc = sh_count(order);
    const int attrs = (channels * nc + 3) / 4;
    const char* lane = "xyzw";
    // GLSL ES: highp parameters and results, and a precision statement for the body's locals.
    const std::string hp = o.es ? "highp " : "";
    const std::string body_precision = o.es ? "    precision highp float;\n" : "";
    std::string s = fmt::format("// skybake PRT relighting: SH order {} ({} coefficients), {} transfer; {}.\n", order,
                                nc, channels == 1 ? "grey" : "RGB", o.es ? "GLSL ES (WebGL)" : "GLSL");
    s += fmt::format("{0}vec3 {1}_diffuse({0}vec4 prt[{2}], {0}vec3 light[{3}], {0}vec3 albedo) {{\n", hp, name, attrs,
                     nc);
    s += body_precision;
    // The sign of each term: light[] in o.light_convention, the transfer in skybake's.
    std::vector<char> sign(std::size_t(nc), '+');
    for (int l = 0; l <= order; ++l)
        for (int m = -l; m <= l; ++m)
            if (sh_convention_sign(m, o.light_convention) < 0)
                sign[std::size_t(sh_index(l, m))] = '-';
    if (o.light_convention != ShConvention::Skybake)
        s += fmt::format("// light[]: {} convention (odd-|m| terms enter with a minus sign).\n",
                         sh_convention_name(o.light_convention));
    if (channels == 1) {
        s += "    vec3 b = vec3(0.0);\n";
        for (int i = 0; i < nc; ++i)
            s += fmt::format("    b {}= light[{}] * prt[{}].{};\n", sign[std::size_t(i)], i, i / 4, lane[i % 4]);
    } else {
        s += "    vec3 b = vec3(0.0);\n";
        for (int ch = 0; ch < 3; ++ch)
            for (int i = 0; i < nc; ++i) {
                const int k = ch * nc + i;
                s += fmt::format("    b.{} {}= light[{}].{} * prt[{}].{};\n", lane[ch], sign[std::size_t(i)], i,
                                 lane[ch], k / 4, lane[k % 4]);
            }
    }
    s += "    return albedo * b;\n}\n";
    if (o.phong) {
        ShaderExportOptions e;
        e.function_name = name + "_sky";
        s += export_neural_sky(*o.network, o.es ? ExportLanguage::GlslEs : ExportLanguage::Glsl, e);
        s += fmt::format("// DPRT: Σ_k λ_k sky(g x_k) over {} ({} points), g taking +z to the mirror direction.\n",
                         o.phong->spec, o.phong->size());
        s += fmt::format("{0}vec3 {1}_glossy({0}vec3 n, {0}vec3 v, {0}vec3 sun, {0}float density) {{\n", hp, name);
        s += body_precision;
        s += "    vec3 r = normalize(2.0 * dot(n, v) * n - v);\n"
             "    float sg = r.z >= 0.0 ? 1.0 : -1.0;\n"
             "    float a = -1.0 / (sg + r.z);\n"
             "    float b = r.x * r.y * a;\n"
             "    vec3 t = vec3(1.0 + sg * r.x * r.x * a, sg * b, -sg * r.x);\n"
             "    vec3 u = vec3(b, sg + r.y * r.y * a, -r.y);\n"
             "    vec3 sum = vec3(0.0);\n"
             "    vec3 x;\n";
        for (std::size_t k = 0; k < o.phong->size(); ++k) {
            const glm::dvec3 p = o.phong->points[k];
            s += fmt::format("    x = {} * t + {} * u + {} * r;\n", glsl_float(p.x), glsl_float(p.y), glsl_float(p.z));
            s += fmt::format("    sum += {} * {}_sky(clamp(x.y, -1.0, 1.0), clamp(dot(x, sun), -1.0, 1.0), "
                             "sun.y, density);\n",
                             glsl_float(o.phong->weights[k]), name);
        }
        s += "    return sum;\n}\n";
    }
    return s;
}

} // namespace skybake
