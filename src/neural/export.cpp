// Export of a trained neural sky as one self-contained function with the
// weights baked in (Pietras & Rudnicki, seed 000, section VI: the network runs
// per vertex in a vertex program). GLSL, HLSL, CUDA and C. The arithmetic and
// its order are those of mlp_hd.h (Σ w·a from the first input, then the bias;
// f(x) = 1/(1 + exp2(2x)); (x − 0.05)/0.9 decoding), so the C version matches
// the library's scalar forward pass to rounding.
#include <cmath>
#include <functional>
#include <sstream>

#include <fmt/format.h>

#include "neural/internal.h"
#include "skybake/error.h"

namespace skybake {

using namespace neural;

ExportLanguage parse_export_language(std::string_view text, const std::string& where) {
    if (text == "glsl")
        return ExportLanguage::Glsl;
    if (text == "glsl-es")
        return ExportLanguage::GlslEs;
    if (text == "hlsl")
        return ExportLanguage::Hlsl;
    if (text == "cuda")
        return ExportLanguage::Cuda;
    if (text == "c")
        return ExportLanguage::C;
    throw Error(fmt::format("unknown export format '{}'; use glsl, glsl-es, hlsl, cuda or c", text), where);
}

namespace {

struct Dialect {
    bool shader;       // GLSL/HLSL: return a vector; C/CUDA: write rgb[3]
    const char* suffix; // float literal suffix
    const char* exp2;
    const char* exp;
    const char* vec3;
};

Dialect dialect(ExportLanguage lang) {
    switch (lang) {
    case ExportLanguage::Glsl:
    case ExportLanguage::GlslEs:
        return {true, "", "exp2", "exp", "vec3"};
    case ExportLanguage::Hlsl:
        return {true, "f", "exp2", "exp", "float3"};
    default:
        return {false, "f", "exp2f", "expf", ""};
    }
}

// A float literal that reads back as exactly v (9 significant digits).
std::string lit(float v, const Dialect& d) {
    std::string s = fmt::format("{:.9g}", v);
    if (s.find_first_of(".e") == std::string::npos)
        s += ".0";
    return s + d.suffix;
}

} // namespace

bool valid_shader_identifier(const std::string& s) {
    if (s.empty() || s.size() > 64 || std::isdigit(static_cast<unsigned char>(s[0])))
        return false;
    for (char c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_'))
            return false;
    return s.rfind("gl_", 0) != 0;
}

std::string export_neural_sky(const NeuralSky& net, ExportLanguage lang, const std::string& name) {
    ShaderExportOptions options;
    options.function_name = name;
    return export_neural_sky(net, lang, options);
}

namespace {

// The encoding constants after the weights in the uniform block: max N, the
// log range, then with horizon inputs R0, Rtop − R0, √(Rtop² − R0²) and the
// scale height, then per phase term g and max S (r, g, b).
std::vector<float> encoding_constants(const NeuralSky& net) {
    const MlpHD m = make_mlp_hd(net);
    std::vector<float> c{m.max_n, m.log_range};
    if (m.inputs == kInputsHorizon) {
        const float top = m.Rtop - m.R0;
        c.insert(c.end(), {m.R0, top, sqrtf(top * (2.0f * m.R0 + top)), m.scale_height});
    }
    for (int k = 0; k < m.terms; ++k)
        c.insert(c.end(), {m.term_g[k], m.term_max[k][0], m.term_max[k][1], m.term_max[k][2]});
    return c;
}

} // namespace

std::vector<float> neural_sky_uniform_data(const NeuralSky& net) {
    net.validate("neural sky");
    std::vector<float> data(net.weights);
    const std::vector<float> c = encoding_constants(net);
    data.insert(data.end(), c.begin(), c.end());
    data.resize((data.size() + 3) / 4 * 4, 0.0f);
    return data;
}

namespace {

using Constant = std::function<std::string(float)>;

// The horizon inputs of mlp_hd.h's encode_inputs, operation for operation
// (the C version rounds as the library's scalar pass does).
void emit_horizon_inputs(std::ostringstream& o, const MlpHD& m, const Dialect& d, const Constant& constant) {
    const float top_v = m.Rtop - m.R0;
    const std::string R0 = constant(m.R0), top = constant(top_v);
    const std::string H = constant(sqrtf(top_v * (2.0f * m.R0 + top_v)));
    const std::string scale = constant(m.scale_height);
    const std::string one = lit(1.0f, d), zero = lit(0.0f, d), two = lit(2.0f, d);
    const std::string sqrt_ = d.shader ? "sqrt" : "sqrtf", log_ = d.shader ? "log" : "logf";
    const std::string abs_ = d.shader ? "abs" : "fabsf";
    const std::string gap = lit(kHorizonGap, d), span = lit(kHorizonSpan, d);
    auto view_input = [&](const std::string& x) { // g + (1 − g) clamp(x, 0, 1)
        return fmt::format("({3} + {4} * ({0} > {1} ? ({0} < {2} ? {0} : {2}) : {1}))", x, zero, one, gap, span);
    };
    o << "    // horizon inputs: ray length split at the horizon, cos b0, cos t0, altitude coordinate\n";
    o << fmt::format("    float h = -{} * {}(density);\n", scale, log_);
    o << fmt::format("    h = h > {} ? (h < {} ? h : {}) : {};\n", zero, top, top, zero);
    o << fmt::format("    float r = {} + h;\n", R0);
    o << fmt::format("    float rho = {}(h * ({} * {} + h));\n", sqrt_, two, R0);
    o << "    float rc = r * cos_view_zenith;\n";
    o << fmt::format("    float arc = {}(rc);\n", abs_);
    o << "    float in0;\n";
    o << fmt::format("    if (cos_view_zenith < {} && arc >= rho) {{\n", zero);
    o << "        float disc = (arc - rho) * (arc + rho);\n";
    o << fmt::format("        float dd = -rc - {}(disc > {} ? disc : {});\n", sqrt_, zero, zero);
    o << "        float span = rho - h;\n";
    o << fmt::format("        float t = span > {} ? (dd - h) / span : {};\n", zero, zero);
    o << fmt::format("        in0 = -{};\n", view_input("t"));
    o << "    } else {\n";
    o << fmt::format("        float disc = rc * rc + ({} - h) * ({} * {} + {} + h);\n", top, two, R0, top);
    o << fmt::format("        float dd = -rc + {}(disc > {} ? disc : {});\n", sqrt_, zero, zero);
    o << fmt::format("        float span = rho + {} - ({} - h);\n", H, top);
    o << fmt::format("        float t = span > {} ? (dd - ({} - h)) / span : {};\n", zero, top, zero);
    o << fmt::format("        in0 = {};\n", view_input("t"));
    o << "    }\n";
    o << "    float in1 = cos_view_sun, in2 = cos_sun_zenith;\n";
    o << fmt::format("    float in3 = {} * rho / {} - {};\n", two, H, one);
}

// sky::phase_value for one term at mu = cos_view_sun, with the same operation order.
std::string phase_expression(int kind, const std::string& g, float g_value, bool literal_g, const Dialect& d) {
    const float pi = 3.14159265358979f;
    const std::string mu = "cos_view_sun", one = lit(1.0f, d), sqrt_ = d.shader ? "sqrt" : "sqrtf";
    // d = 1 + g² − 2 g mu, and the constants of each formula: literals when g is known.
    const std::string den = literal_g ? fmt::format("({} - {} * {})", lit(1.0f + g_value * g_value, d),
                                                    lit(2.0f * g_value, d), mu)
                                      : fmt::format("({0} + {1} * {1} - {2} * {1} * {3})", one, g, lit(2.0f, d), mu);
    const std::string dd = fmt::format("({0} * {1}({0}))", den, sqrt_);
    const std::string one_minus_g2 = literal_g ? lit(1.0f - g_value * g_value, d) : fmt::format("({0} - {1} * {1})", one, g);
    switch (kind) {
    case 1:
        return fmt::format("{} * ({} + {} * {})", lit(3.0f / (16.0f * pi), d), one, mu, mu);
    case 2:
        return literal_g ? fmt::format("{} / {}", lit(0.25f / pi * (1.0f - g_value * g_value), d), dd)
                         : fmt::format("{} * {} / {}", lit(0.25f / pi, d), one_minus_g2, dd);
    case 3: {
        const std::string a = literal_g ? lit(3.0f * (1.0f - g_value * g_value), d)
                                        : fmt::format("{} * {}", lit(3.0f, d), one_minus_g2);
        const std::string b = literal_g ? lit(8.0f * pi * (2.0f + g_value * g_value), d)
                                        : fmt::format("{} * ({} + {} * {})", lit(8.0f * pi, d), lit(2.0f, d), g, g);
        return fmt::format("{} * ({} + {} * {}) / ({} * {} * {}({}))", a, one, mu, mu, b, den, sqrt_, den);
    }
    case 4:
        return fmt::format("{} / ({} * {} * {}({}))", one_minus_g2, lit(16.0f * pi, d), den, sqrt_, den);
    default:
        return lit(0.0f, d);
    }
}

// I = Σ_k P_k(cos b0) S_k with each channel of S_k = max · e^(D (x' − 1)), 0 below the offset.
void emit_phase_factored_decoding(std::ostringstream& o, const NeuralSky& net, const MlpHD& m, const Dialect& d,
                                  const std::vector<std::string>& outputs, const std::string& log_range,
                                  const Constant& constant) {
    const std::string inv = lit(1.0f / kEncodeScale, d), off = lit(kEncodeOffset, d), zero = lit(0.0f, d);
    const std::string one = lit(1.0f, d);
    o << "    // decoding: per phase term, the exact phase function times S (log-encoded per channel)\n";
    o << fmt::format("    float cr = {0}, cg = {0}, cb = {0};\n", zero);
    for (int k = 0; k < m.terms; ++k) {
        const std::string g = constant(m.term_g[k]);
        const bool lit_g = g.find('[') == std::string::npos;
        o << fmt::format("    {{ // {} ({})\n", net.encoding.terms[std::size_t(k)].component,
                         phase_function_name(net.encoding.terms[std::size_t(k)].phase));
        o << fmt::format("        float p = {};\n", phase_expression(m.term_phase[k], g, m.term_g[k], lit_g, d));
        const char* ch[] = {"cr", "cg", "cb"};
        for (int c = 0; c < 3; ++c) {
            const std::string mx = constant(m.term_max[k][c]);
            o << fmt::format("        float v{} = ({} - {}) * {};\n", c, outputs[std::size_t(3 * k + c)], off, inv);
            o << fmt::format("        {} += p * (v{} > {} ? {} * {}({} * (v{} - {})) : {});\n", ch[c], c, zero, mx,
                             d.exp, log_range, c, one, zero);
        }
        o << "    }\n";
    }
    if (d.shader)
        o << fmt::format("    return {}(cr, cg, cb);\n", d.vec3);
    else
        o << "    rgb[0] = cr;\n    rgb[1] = cg;\n    rgb[2] = cb;\n";
}

} // namespace

std::string export_neural_sky(const NeuralSky& net, ExportLanguage lang, const ShaderExportOptions& options) {
    const std::string& name = options.function_name;
    net.validate("neural sky");
    const bool es = lang == ExportLanguage::GlslEs;
    // GLSL ES: the function computes in highp whatever the shader's default
    // precision is (its parameters, return value and block are qualified; a
    // precision statement inside the body covers its locals).
    const std::string hp = es ? "highp " : "";
    const bool ubo = options.uniform_block && (lang == ExportLanguage::Glsl || es);
    if (ubo && !valid_shader_identifier(options.block_name))
        throw Error(fmt::format("'{}' is not a valid uniform block name", options.block_name), "block_name");
    if (!valid_shader_identifier(name))
        throw Error(fmt::format("'{}' is not a valid function name (letters, digits and _, not starting with a digit "
                                "or gl_)",
                                name),
                    "name");
    const Dialect d = dialect(lang);
    const Layout lay = make_layout(net.topology);
    const std::string f = name + "_f";
    // Uniform block: value i of neural_sky_uniform_data is NAME_w[i / 4].xyzw[i % 4].
    const std::string wname = name + "_w";
    auto uniform = [&](std::size_t i) { return fmt::format("{}[{}].{}", wname, i / 4, "xyzw"[i % 4]); };
    const std::size_t n_weights = net.weights.size();
    const MlpHD m = make_mlp_hd(net);
    const std::size_t n_block = (n_weights + encoding_constants(net).size() + 3) / 4;
    std::ostringstream o;
    const char* lang_name[] = {"GLSL", "HLSL", "CUDA", "C", "GLSL ES (WebGL)"};
    if (ubo) // the text must not depend on the weights or what they were trained on
        o << fmt::format("// {}: neural sky (skybake), {} network, {} weights in a uniform block.\n", name,
                         net.topology.name(), net.topology.weight_count());
    else
        o << fmt::format("// {}: neural sky (skybake), {} network, {} weights, trained on atmosphere \"{}\".\n", name,
                         net.topology.name(), net.topology.weight_count(), net.atmosphere.name);
    o << "// Pietras & Rudnicki, \"GPU-based multi-layer perceptron as efficient method for approximation\n"
         "// complex light models in per-vertex lighting\": the sky colour I(cos a0, cos b0, cos t0, rho0).\n";
    o << "// Inputs: cos_view_zenith = V.U, cos_view_sun = V.L, cos_sun_zenith = U.L (V: view direction,\n"
         "// U: local vertical at the observer, L: direction to the sun, all unit vectors) and density =\n"
         "// relative density of the first atmosphere component at the observer, in (0, 1].\n";
    o << "// Output: single-scattered radiance per unit sun irradiance (1/sr), linear RGB; multiply by the\n";
    if (ubo)
        o << fmt::format("// sun's irradiance. Valid in vertex and fragment shaders; the weights come from the uniform\n"
                         "// block {} (std140, {} vec4s: the weights, then the encoding's constants).\n",
                         options.block_name, n_block);
    else
        o << "// sun's irradiance. Valid in vertex and fragment shaders (no uniforms, no textures).\n";
    o << fmt::format("// Language: {}. Generated by `skybake sky export`; do not edit the numbers.\n",
                     lang_name[int(lang)]);
    const char* qual = "";
    switch (lang) {
    case ExportLanguage::C:
        o << "#include <math.h>\n\n";
        qual = "static ";
        break;
    case ExportLanguage::Cuda:
        o << "#include <math.h>\n"
             "#ifndef SKYBAKE_SKY_HD\n"
             "#if defined(__CUDACC__)\n"
             "#define SKYBAKE_SKY_HD __host__ __device__ inline\n"
             "#else\n"
             "#define SKYBAKE_SKY_HD inline\n"
             "#endif\n"
             "#endif\n\n";
        qual = "SKYBAKE_SKY_HD ";
        break;
    default:
        o << "\n";
        if (ubo)
            o << fmt::format("layout(std140) uniform {} {{\n    {}vec4 {}[{}];\n}};\n\n", options.block_name, hp,
                             wname, n_block);
        break;
    }
    // Activation f(x) = 1/(1 + 2^(2x)).
    o << fmt::format("{}{}float {}({}float x) {{ return {} / ({} + {}({} * x)); }}\n\n", qual, hp, f, hp,
                     lit(1.0f, d), lit(1.0f, d), d.exp2, lit(2.0f, d));
    const std::string params = fmt::format("{0}float cos_view_zenith, {0}float cos_view_sun, {0}float cos_sun_zenith, "
                                           "{0}float density",
                                           hp);
    if (d.shader)
        o << fmt::format("{}{} {}({}) {{\n", hp, d.vec3, name, params);
    else
        o << fmt::format("{}void {}({}, float rgb[3]) {{\n", lang == ExportLanguage::C ? "" : qual, name, params);
    if (es)
        o << "    precision highp float;\n";
    const char* cst = d.shader ? "" : "const ";
    // Constants of the encoding: literals, or values of the uniform block after the weights.
    std::size_t next_uniform = n_weights;
    auto constant = [&](float v) { return ubo ? uniform(next_uniform++) : lit(v, d); };
    const std::string max_n = constant(m.max_n);
    const std::string log_range = constant(m.log_range);
    if (m.inputs == kInputsHorizon)
        emit_horizon_inputs(o, m, d, constant);
    else
        o << "    " << cst << "float in0 = cos_view_zenith, in1 = cos_view_sun, in2 = cos_sun_zenith, in3 = density;\n";
    std::vector<std::string> out_names{"R", "G", "B", "M"};
    if (m.output_kind == kOutputsPhaseFactored) {
        out_names.clear();
        for (const PhaseTerm& t : net.encoding.terms)
            for (const char* c : {"r", "g", "b"})
                out_names.push_back(fmt::format("S {} {}", t.component, c));
    }
    std::vector<std::string> outputs;
    for (int s = 0; s < lay.subnets; ++s) {
        const float* w = net.weights.data() + std::size_t(s) * std::size_t(lay.subnet_params);
        o << (lay.subnets == 1 ? std::string("    // shared network\n")
                               : fmt::format("    // sub-network {}\n", out_names[std::size_t(s)]));
        std::vector<std::string> prev{"in0", "in1", "in2", "in3"};
        for (std::size_t l = 0; l < lay.layers.size(); ++l) {
            const LayerLayout& L = lay.layers[l];
            std::vector<std::string> cur;
            for (int r = 0; r < L.out; ++r) {
                const std::string v = fmt::format("s{}_{}_{}", s, l + 1, r);
                std::string e;
                const std::size_t base = std::size_t(s) * std::size_t(lay.subnet_params);
                for (int c = 0; c < L.in; ++c) {
                    const float wv = w[L.w_offset + r * L.in + c];
                    if (ubo)
                        e += fmt::format("{}{} * {}", c == 0 ? "" : " + ",
                                         uniform(base + std::size_t(L.w_offset + r * L.in + c)), prev[std::size_t(c)]);
                    else if (c == 0)
                        e += fmt::format("{} * {}", lit(wv, d), prev[std::size_t(c)]);
                    else if (std::signbit(wv))
                        e += fmt::format(" - {} * {}", lit(-wv, d), prev[std::size_t(c)]);
                    else
                        e += fmt::format(" + {} * {}", lit(wv, d), prev[std::size_t(c)]);
                }
                const float bv = w[L.b_offset + r];
                if (ubo)
                    e += " + " + uniform(base + std::size_t(L.b_offset + r));
                else
                    e += std::signbit(bv) ? fmt::format(" - {}", lit(-bv, d)) : fmt::format(" + {}", lit(bv, d));
                o << fmt::format("    {}float {} = {}({});\n", d.shader ? "" : "const ", v, f, e);
                cur.push_back(v);
            }
            prev = std::move(cur);
        }
        for (const std::string& v : prev)
            outputs.push_back(v);
    }
    const std::string inv = lit(1.0f / kEncodeScale, d), off = lit(kEncodeOffset, d), zero = lit(0.0f, d);
    if (m.output_kind == kOutputsPhaseFactored) {
        emit_phase_factored_decoding(o, net, m, d, outputs, log_range, constant);
        o << "}\n";
        return o.str();
    }
    o << "    // decoding: (x - 0.05)/0.9, values below 0.05 are 0; N from the brightness output\n";
    o << fmt::format("    {}float m = ({} - {}) * {};\n", cst, outputs[3], off, inv);
    if (d.shader)
        o << fmt::format("    if (!(m > {})) return {}({});\n", zero, d.vec3, zero);
    else
        o << fmt::format("    if (!(m > {})) {{ rgb[0] = rgb[1] = rgb[2] = {}; return; }}\n", zero, zero);
    if (net.encoding.brightness == BrightnessEncoding::Linear)
        o << fmt::format("    {}float n = m * {};\n", cst, max_n);
    else
        o << fmt::format("    {}float n = {} * {}({} * (m - {}));\n", cst, max_n, d.exp, log_range, lit(1.0f, d));
    for (int k = 0; k < 3; ++k)
        o << fmt::format("    {}float c{} = ({} - {}) * {};\n", cst, k, outputs[std::size_t(k)], off, inv);
    if (d.shader)
        o << fmt::format("    return max({}(c0, c1, c2), {}({})) * n;\n", d.vec3, d.vec3, zero);
    else
        for (int k = 0; k < 3; ++k)
            o << fmt::format("    rgb[{}] = (c{} > {} ? c{} : {}) * n;\n", k, k, zero, k, zero);
    o << "}\n";
    return o.str();
}

} // namespace skybake
