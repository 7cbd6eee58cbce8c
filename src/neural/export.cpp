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
// scale height; then with residual outputs R0, Rtop − R0, the scale height,
// per exponential component its scale height and extinction (r, g, b), per
// term its scattering (r, g, b), per term g, and with multiple scattering the
// largest multiply scattered light (r, g, b), or for a marched term ψ's lowest
// sun cosine and its 3 × kPsiCoefficients coefficients; else per phase term g and
// max S (r, g, b). An aerosol family ends the list with its input's a and b
// and the run-time aerosol amount. This is the order the exporter reads them in.
std::vector<float> encoding_constants(const NeuralSky& net) {
    const MlpHD m = make_mlp_hd(net);
    std::vector<float> c{m.max_n, m.log_range};
    if (m.inputs == kInputsHorizon) {
        const float top = m.Rtop - m.R0;
        c.insert(c.end(), {m.R0, top, sqrtf(top * (2.0f * m.R0 + top)), m.scale_height});
    }
    if (m.output_kind == kOutputsResidual) {
        c.insert(c.end(), {m.R0, m.Rtop - m.R0, m.scale_height});
        for (int e = 0; e < m.ext_count; ++e)
            c.insert(c.end(), {m.ext_height[e], m.ext_beta[e][0], m.ext_beta[e][1], m.ext_beta[e][2]});
        for (int k = 0; k < m.terms; ++k)
            c.insert(c.end(), {m.term_beta[k][0], m.term_beta[k][1], m.term_beta[k][2]});
        for (int k = 0; k < m.terms; ++k)
            c.push_back(m.term_g[k]);
        if (m.multiple && m.multiple_march) { // ψ's sun range and its polynomial, r then g then b
            c.push_back(m.psi_mu_min);
            for (int ch = 0; ch < 3; ++ch)
                c.insert(c.end(), m.psi[ch], m.psi[ch] + kPsiCoefficients);
        } else if (m.multiple) {
            c.insert(c.end(), {m.multiple_max[0], m.multiple_max[1], m.multiple_max[2]});
        }
        if (m.family)
            c.insert(c.end(), {m.family_a, m.family_b, m.aerosol});
        return c;
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

// mlp_hd.h's view_ray_at up to the ray's length: the observer's altitude
// PREFIXh (from `altitude`, clamped to the atmosphere), PREFIXr, PREFIXrho and
// PREFIXrc = r cos_view_zenith, PREFIXarc = |PREFIXrc|.
void emit_observer(std::ostringstream& o, const std::string& p, const std::string& altitude, const std::string& R0,
                   const std::string& top, const Dialect& d) {
    const std::string zero = lit(0.0f, d), two = lit(2.0f, d);
    o << fmt::format("    float {}h = {};\n", p, altitude);
    o << fmt::format("    {0}h = {0}h > {1} ? ({0}h < {2} ? {0}h : {2}) : {1};\n", p, zero, top);
    o << fmt::format("    float {0}r = {1} + {0}h;\n", p, R0);
    o << fmt::format("    float {0}rho = {1}({0}h * ({2} * {3} + {0}h));\n", p, d.shader ? "sqrt" : "sqrtf", two, R0);
    o << fmt::format("    float {0}rc = {0}r * cos_view_zenith;\n", p);
    o << fmt::format("    float {0}arc = {1}({0}rc);\n", p, d.shader ? "abs" : "fabsf");
}

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
    emit_observer(o, "", fmt::format("-{} * {}(density)", scale, log_), R0, top, d);
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

// Opens the block of phase term k: its name, and p = its phase function at
// cos_view_sun (g from `constant`, the term's first constant).
void open_phase_term(std::ostringstream& o, const NeuralSky& net, const MlpHD& m, int k, const Dialect& d,
                     const Constant& constant) {
    const std::string g = constant(m.term_g[k]);
    const bool lit_g = g.find('[') == std::string::npos;
    o << fmt::format("    {{ // {} ({})\n", net.encoding.terms[std::size_t(k)].component,
                     phase_function_name(net.encoding.terms[std::size_t(k)].phase));
    o << fmt::format("        float p = {};\n", phase_expression(m.term_phase[k], g, m.term_g[k], lit_g, d));
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
        open_phase_term(o, net, m, k, d, constant);
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

// The residual outputs' helpers, mlp_hd.h's chapman_depth and chapman_segment,
// written once in GLSL and adapted: float suffixes and C's function names.
std::string residual_helpers(const std::string& name, const Dialect& d, const std::string& qual,
                             const std::string& hp) {
    std::string t = R"(QFLOAT NAME_periapsis(FLOAT h, FLOAT R0, FLOAT cos_chi) {
    FLOAT s2 = (1.0 - cos_chi) * (1.0 + cos_chi);
    FLOAT s = sqrt(s2 > 0.0 ? s2 : 0.0);
    FLOAT h0 = h * s - R0 * (cos_chi * cos_chi) / (1.0 + s);
    return h0 > 0.0 ? h0 : 0.0;
}

QFLOAT NAME_chapman(FLOAT h, FLOAT R0, FLOAT H, FLOAT cos_chi) {
    FLOAT k = sqrt((R0 + h) / H), kc = k * cos_chi;
    return k / (0.661 * kc + 0.339 * sqrt(kc * kc + 5.51));
}

QFLOAT NAME_depth(FLOAT h, FLOAT R0, FLOAT H, FLOAT cos_chi, FLOAT rho_h) {
    if (cos_chi >= 0.0) return H * rho_h * NAME_chapman(h, R0, H, cos_chi);
    FLOAT h0 = NAME_periapsis(h, R0, cos_chi);
    return H * (2.0 * exp(-h0 / H) * NAME_chapman(h0, R0, H, 0.0) - rho_h * NAME_chapman(h, R0, H, -cos_chi));
}

QFLOAT NAME_segment(FLOAT R0, FLOAT H, FLOAT ha, FLOAT ca, FLOAT rho_a, FLOAT hb, FLOAT cb, FLOAT rho_b) {
    FLOAT fa = H * rho_a * NAME_chapman(ha, R0, H, abs(ca));
    FLOAT fb = H * rho_b * NAME_chapman(hb, R0, H, abs(cb));
    if (ca >= 0.0) return fa - fb;
    if (cb < 0.0) return fb - fa;
    FLOAT h0 = NAME_periapsis(ha, R0, ca);
    return 2.0 * H * exp(-h0 / H) * NAME_chapman(h0, R0, H, 0.0) - fa - fb;
}

)";
    auto replace_all = [&](const std::string& from, const std::string& to) {
        for (std::size_t at = t.find(from); at != std::string::npos; at = t.find(from, at + to.size()))
            t.replace(at, from.size(), to);
    };
    replace_all("QFLOAT", qual + hp + "float");
    replace_all("FLOAT", hp + "float");
    replace_all("NAME", name);
    if (!d.shader) {
        replace_all("sqrt(", "sqrtf(");
        replace_all("exp(", "expf(");
        replace_all("abs(", "fabsf(");
    }
    if (*d.suffix) // float literals (digits '.' digits) take the suffix
        for (std::size_t i = 1; i + 1 < t.size(); ++i)
            if (t[i] == '.' && std::isdigit(static_cast<unsigned char>(t[i - 1])) &&
                std::isdigit(static_cast<unsigned char>(t[i + 1]))) {
                std::size_t j = i + 1;
                while (j < t.size() && std::isdigit(static_cast<unsigned char>(t[j])))
                    ++j;
                t.insert(j, d.suffix);
                i = j;
            }
    return t;
}

// The analytic march's constants as the function reads them (literals, or
// values of the uniform block).
struct MarchConstants {
    std::string R0, top, scale;
    std::vector<std::string> H, be, bs; // per component; per component and channel; per term and channel
};

// mlp_hd.h's analytic_terms, operation for operation, into A<k>r, A<k>g, A<k>b.
MarchConstants emit_analytic_terms(std::ostringstream& o, const std::string& name, const MlpHD& m, const Dialect& d,
                                   const Constant& constant) {
    const std::string R0 = constant(m.R0), top = constant(m.Rtop - m.R0), scale = constant(m.scale_height);
    std::vector<std::string> H(std::size_t(m.ext_count)), be(std::size_t(3 * m.ext_count)),
        bs(std::size_t(3 * m.terms));
    // An aerosol family scales its component's coefficients by `aerosol`, as analytic_terms does.
    for (int e = 0; e < m.ext_count; ++e) {
        H[std::size_t(e)] = constant(m.ext_height[e]);
        for (int c = 0; c < 3; ++c) {
            be[std::size_t(3 * e + c)] = constant(m.ext_beta[e][c]);
            if (m.family && e == m.family_ext)
                be[std::size_t(3 * e + c)] = "(" + be[std::size_t(3 * e + c)] + " * aerosol)";
        }
    }
    for (int k = 0; k < m.terms; ++k)
        for (int c = 0; c < 3; ++c) {
            bs[std::size_t(3 * k + c)] = constant(m.term_beta[k][c]);
            if (m.family && k == m.family_term)
                bs[std::size_t(3 * k + c)] = "(" + bs[std::size_t(3 * k + c)] + " * aerosol)";
        }
    const std::string zero = lit(0.0f, d), one = lit(1.0f, d), two = lit(2.0f, d), half = lit(0.5f, d);
    const std::string sqrt_ = d.shader ? "sqrt" : "sqrtf", log_ = d.shader ? "log" : "logf";
    const std::string exp_ = d.exp, abs_ = d.shader ? "abs" : "fabsf";
    const char* ch = "rgb";
    o << "    // residual outputs: the analytic single scattering A per term (skybake's analytic_terms)\n";
    o << fmt::format("    float a_u = (density - {0}) / (density + {0}), a_u2 = a_u * a_u;\n", one);
    emit_observer(o, "a_",
                  fmt::format("-{} * (density > {} ? {} * a_u * ({} + a_u2 * ({} + a_u2 * {})) : {}(density))", scale,
                              lit(0.97f, d), two, one, lit(0.333333343f, d), lit(0.2f, d), log_),
                  R0, top, d);
    // an observer above the top whose ray misses the atmosphere sees no air (misses_atmosphere)
    o << "    bool a_miss;\n";
    o << "    {\n";
    o << fmt::format("        float hr = -{} * (density > {} ? {} * a_u * ({} + a_u2 * ({} + a_u2 * {})) : {}(density));\n",
                     scale, lit(0.97f, d), two, one, lit(0.333333343f, d), lit(0.2f, d), log_);
    o << fmt::format("        float r = {0} + hr, rt = {0} + {1};\n", R0, top);
    o << fmt::format("        float s2 = ({0} - cos_view_zenith) * ({0} + cos_view_zenith);\n", one);
    o << fmt::format("        a_miss = hr > {} && (cos_view_zenith >= {} || r * r * s2 >= rt * rt);\n", top, zero);
    o << "    }\n";
    o << "    float a_d;\n";
    o << fmt::format("    if (cos_view_zenith < {} && a_arc >= a_rho) {{\n", zero);
    o << "        float disc = (a_arc - a_rho) * (a_arc + a_rho);\n";
    o << fmt::format("        a_d = a_rho * a_rho / (a_arc + {}(disc > {} ? disc : {}));\n", sqrt_, zero, zero);
    o << "    } else {\n";
    o << fmt::format("        float k = ({} - a_h) * ({} * {} + {} + a_h);\n", top, two, R0, top);
    o << "        float disc = a_rc * a_rc + k;\n";
    o << fmt::format("        float s = {}(disc > {} ? disc : {});\n", sqrt_, zero, zero);
    o << fmt::format("        a_d = a_rc > {} ? k / (a_rc + s) : -a_rc + s;\n", zero);
    o << "    }\n";
    o << "    // the planet's shadow on the ray: [a_lo, a_hi]\n";
    o << fmt::format("    float a_lo = {}, a_hi = a_d;\n", zero);
    o << "    float a_c = a_r * cos_sun_zenith;\n";
    o << "    bool a_sh = true;\n";
    o << fmt::format("    if (cos_view_sun > {0}) {{ float t = -a_c / cos_view_sun; a_hi = a_hi < t ? a_hi : t; }}\n"
                     "    else if (cos_view_sun < {0}) {{ float t = -a_c / cos_view_sun; a_lo = a_lo > t ? a_lo : t; }}\n"
                     "    else a_sh = a_c < {0};\n",
                     zero);
    o << fmt::format("    float a_A = ({0} - cos_view_sun) * ({0} + cos_view_sun);\n", one);
    o << fmt::format("    float a_B = {} * a_r * (cos_view_zenith - cos_sun_zenith * cos_view_sun);\n", two);
    o << "    float a_C = (a_rho - a_c) * (a_rho + a_c);\n";
    o << fmt::format("    if (a_A <= {}) {{\n", lit(1e-12f, d));
    o << fmt::format("        if (a_B > {0}) {{ float t = -a_C / a_B; a_hi = a_hi < t ? a_hi : t; }}\n"
                     "        else if (a_B < {0}) {{ float t = -a_C / a_B; a_lo = a_lo > t ? a_lo : t; }}\n"
                     "        else a_sh = a_sh && a_C < {0};\n",
                     zero);
    o << "    } else {\n";
    o << fmt::format("        float D = a_B * a_B - {} * a_A * a_C;\n", lit(4.0f, d));
    o << fmt::format("        if (D > {}) {{\n", zero);
    o << fmt::format("            float sq = {}(D);\n", sqrt_);
    o << fmt::format("            float q = -{} * (a_B + (a_B < {} ? -sq : sq));\n", half, zero);
    o << fmt::format("            float ta = q / a_A, tb = q != {} ? a_C / q : -ta;\n", zero);
    o << "            float t0 = ta < tb ? ta : tb, t1 = ta < tb ? tb : ta;\n";
    o << "            a_lo = a_lo > t0 ? a_lo : t0;\n";
    o << "            a_hi = a_hi < t1 ? a_hi : t1;\n";
    o << "        } else {\n            a_sh = false;\n        }\n";
    o << "    }\n";
    o << "    a_sh = a_sh && a_lo < a_hi;\n";
    o << "    if (a_miss) {\n        a_d = " << zero << ";\n        a_sh = false;\n    }\n";
    o << "    // the march over the lit parts\n";
    o << fmt::format("    float a_rho2 = a_rho * a_rho, a_2rmu = {} * a_r * cos_view_zenith;\n", two);
    // The view's depth: a trapezoid sum from the previous point, or (a family) Chapman integrals from the observer.
    if (m.family)
        o << fmt::format("    float tau_r = {0}, tau_g = {0}, tau_b = {0};\n", zero);
    else
        o << fmt::format("    float tau_r = {0}, tau_g = {0}, tau_b = {0}, t_prev = {0};\n", zero);
    for (int e = 0; e < m.ext_count; ++e)
        o << fmt::format("    float {0}{1} = {2}(-a_h / {3});\n", m.family ? "obs" : "prev", e, exp_, H[std::size_t(e)]);
    for (int k = 0; k < m.terms; ++k)
        o << fmt::format("    float A{0}r = {1}, A{0}g = {1}, A{0}b = {1};\n", k, zero);
    o << "    for (int part = 0; part < 2; ++part) {\n";
    o << fmt::format("        float a = part == 0 ? {} : (a_sh ? a_hi : a_d);\n", zero);
    o << "        float b = part == 0 ? (a_sh ? a_lo : a_d) : a_d;\n";
    o << "        if (!(b > a)) continue;\n";
    o << fmt::format("        float dt = (b - a) * {};\n", lit(1.0f / float(kResidualSteps), d));
    o << "        float h_end0, h_end1, h_end2, r_end0, c_end0, r_end1, c_end1;\n";
    for (int j = 0; j < 3; ++j) {
        o << "        {\n";
        if (j == 2)
            o << "            float t = -a_r * cos_view_zenith;\n            t = t < a ? a : (t > b ? b : t);\n";
        else
            o << fmt::format("            float t = {};\n", j == 0 ? "a" : "b");
        o << "            float q = a_rho2 + t * (a_2rmu + t);\n";
        o << fmt::format("            q = q > {0} ? q : {0};\n", zero);
        o << fmt::format("            h_end{0} = q / ({1}(q + {2} * {2}) + {2});\n", j, sqrt_, R0);
        if (j < 2) {
            o << fmt::format("            r_end{0} = {1} + h_end{0};\n", j, R0);
            o << fmt::format("            c_end{0} = (a_r * cos_view_zenith + t) / r_end{0};\n", j);
        }
        o << "        }\n";
    }
    for (int e = 0; e < m.ext_count; ++e)
        o << fmt::format("        float sum{} = {};\n", e, zero);
    for (int k = 0; k < m.terms; ++k)
        o << fmt::format("        float P{0}r = {1}, P{0}g = {1}, P{0}b = {1};\n", k, zero);
    o << fmt::format("        float fk = {};\n", half);
    o << fmt::format("        for (int k = 0; k < {}; ++k) {{\n", kResidualSteps);
    o << "            float t = a + fk * dt;\n";
    o << fmt::format("            fk += {};\n", one);
    o << "            float q = a_rho2 + t * (a_2rmu + t);\n";
    o << fmt::format("            q = q > {0} ? q : {0};\n", zero);
    o << fmt::format("            float hp = q / ({0}(q + {1} * {1}) + {1});\n", sqrt_, R0);
    o << fmt::format("            float rp = {} + hp;\n", R0);
    o << "            float cos_chi = (a_r * cos_sun_zenith + t * cos_view_sun) / rp;\n";
    o << fmt::format("            float sun_r = {0}, sun_g = {0}, sun_b = {0};\n", zero);
    if (m.family)
        o << fmt::format("            tau_r = {0}; tau_g = {0}; tau_b = {0};\n", zero);
    for (int e = 0; e < m.ext_count; ++e) {
        o << fmt::format("            float dens{} = {}(-hp / {});\n", e, exp_, H[std::size_t(e)]);
        o << fmt::format("            sum{0} += dens{0} * dt;\n", e);
        o << "            {\n";
        if (m.family)
            o << fmt::format("                float view = {}_segment({}, {}, a_h, cos_view_zenith, obs{}, hp, "
                             "(a_r * cos_view_zenith + t) / rp, dens{});\n",
                             name, R0, H[std::size_t(e)], e, e);
        else
            o << fmt::format("                float view = {0} * (dens{1} + prev{1}) * (t - t_prev);\n", half, e);
        o << fmt::format("                float depth = {}_depth(hp, {}, {}, cos_chi, dens{});\n", name, R0,
                         H[std::size_t(e)], e);
        for (int c = 0; c < 3; ++c)
            o << fmt::format("                tau_{0} += {1} * view;\n                sun_{0} += {1} * depth;\n",
                             ch[c], be[std::size_t(3 * e + c)]);
        o << "            }\n";
        if (!m.family)
            o << fmt::format("            prev{0} = dens{0};\n", e);
    }
    if (!m.family)
        o << "            t_prev = t;\n";
    for (int c = 0; c < 3; ++c) {
        o << "            {\n";
        o << fmt::format("                float tr = {0}(-(tau_{1} + sun_{1})) * dt;\n", exp_, ch[c]);
        for (int k = 0; k < m.terms; ++k)
            o << fmt::format("                P{}{} += {} * dens{} * tr;\n", k, ch[c], bs[std::size_t(3 * k + c)],
                             m.term_ext[k]);
        o << "            }\n";
    }
    o << "        }\n";
    for (int k = 0; k < m.terms; ++k) {
        const int e = m.term_ext[k];
        o << "        {\n";
        o << fmt::format("            float exact = {0}_segment({1}, {2}, h_end0, c_end0, {3}(-h_end0 / {2}), "
                         "h_end1, c_end1, {3}(-h_end1 / {2}));\n",
                         name, R0, H[std::size_t(e)], exp_);
        o << fmt::format("            float g = (h_end0 + h_end1 - {} * h_end2) / {};\n", two, H[std::size_t(e)]);
        o << fmt::format("            float w = (g - {0}) * {0};\n", half);
        o << fmt::format("            w = w > {0} ? (w < {1} ? w : {1}) : {0};\n", zero, one);
        o << fmt::format("            w = w * w * ({} - {} * w);\n", lit(3.0f, d), two);
        o << fmt::format("            float ratio = sum{0} > {1} && exact > {1} ? exact / sum{0} : {2};\n", e, zero,
                         one);
        o << fmt::format("            float sc = {0} + w * (ratio - {0});\n", one);
        for (int c = 0; c < 3; ++c)
            o << fmt::format("            A{0}{1} += sc * P{0}{1};\n", k, ch[c]);
        o << "        }\n";
    }
    o << "    }\n";
    return {R0, top, scale, H, be, bs};
}

// mlp_hd.h's analytic_multiple_along (and psi_log), operation for
// operation, into M_r, M_g, M_b; ψ's constants from `constant`.
void emit_analytic_multiple(std::ostringstream& o, const MlpHD& m, const Dialect& d, const MarchConstants& mc,
                            const Constant& constant) {
    const std::string mu_min = constant(m.psi_mu_min);
    std::vector<std::string> a(std::size_t(3 * kPsiCoefficients));
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < kPsiCoefficients; ++i)
            a[std::size_t(c * kPsiCoefficients + i)] = constant(m.psi[c][i]);
    const std::string zero = lit(0.0f, d), one = lit(1.0f, d), two = lit(2.0f, d), half = lit(0.5f, d);
    const std::string sqrt_ = d.shader ? "sqrt" : "sqrtf", log_ = d.shader ? "log" : "logf", exp_ = d.exp;
    const char* ch = "rgb";
    o << "    // the light scattered more than once: an isotropic march of the sky's mean radiance psi (skybake's\n"
         "    // analytic_multiple), which the network corrects\n";
    o << fmt::format("    float M_r = {0}, M_g = {0}, M_b = {0};\n", zero);
    o << "    {\n";
    o << "        if (!a_miss) {\n";
    o << fmt::format("        float dt = a_d * {};\n", lit(1.0f / float(kMultipleSteps), d));
    for (int e = 0; e < m.ext_count; ++e)
        o << fmt::format("        float mp{} = {}(-a_h / {});\n", e, exp_, mc.H[std::size_t(e)]);
    o << fmt::format("        float mt_r = {0}, mt_g = {0}, mt_b = {0};\n", zero);
    o << fmt::format("        float fm = {}, fe = {};\n", half, one);
    o << fmt::format("        for (int k = 0; k < {}; ++k) {{\n", kMultipleSteps);
    const char* which[] = {"m", "e"};
    for (int j = 0; j < 2; ++j) {
        o << fmt::format("            float t{0} = f{0} * dt;\n", which[j]);
        o << fmt::format("            float q{0} = a_rho2 + t{0} * (a_2rmu + t{0});\n", which[j]);
        o << fmt::format("            q{0} = q{0} > {1} ? q{0} : {1};\n", which[j], zero);
        o << fmt::format("            float h{0} = q{0} / ({1}(q{0} + {2} * {2}) + {2});\n", which[j], sqrt_, mc.R0);
    }
    o << fmt::format("            float mus = (a_r * cos_sun_zenith + tm * cos_view_sun) / ({} + hm);\n", mc.R0);
    o << "            fm += " << one << ";\n            fe += " << one << ";\n";
    for (int e = 0; e < m.ext_count; ++e) {
        o << fmt::format("            float mid{0} = {1}(-hm / {2});\n", e, exp_, mc.H[std::size_t(e)]);
        o << fmt::format("            float end{0} = {1}(-he / {2});\n", e, exp_, mc.H[std::size_t(e)]);
    }
    // psi_log's arguments, clamped.
    o << fmt::format("            float px = {} * hm / {} - {};\n", two, mc.top, one);
    o << fmt::format("            float py = ({0} * mus - {1} - {2}) / ({1} - {2});\n", two, one, mu_min);
    o << fmt::format("            px = px > -{0} ? (px < {0} ? px : {0}) : -{0};\n", one);
    o << fmt::format("            py = py > -{0} ? (py < {0} ? py : {0}) : -{0};\n", one);
    for (int c = 0; c < 3; ++c) {
        o << "            {\n";
        o << fmt::format("                float dtau = {0}, sca = {0};\n", zero);
        for (int e = 0; e < m.ext_count; ++e)
            o << fmt::format("                dtau += {} * {} * (mp{} + end{}) * dt;\n", mc.be[std::size_t(3 * e + c)],
                             half, e, e);
        for (int k = 0; k < m.terms; ++k)
            o << fmt::format("                sca += {} * mid{};\n", mc.bs[std::size_t(3 * k + c)], m.term_ext[k]);
        o << fmt::format("                float f = dtau > {0} ? ({1} - {2}(-dtau)) / dtau : {1} - dtau * ({3} - dtau * "
                         "({4} - dtau * {5}));\n",
                         lit(0.1f, d), one, exp_, half, lit(0.166666672f, d), lit(0.0416666679f, d));
        o << fmt::format("                float w = {}(-mt_{}) * sca * dt * f;\n", exp_, ch[c]);
        o << fmt::format("                mt_{} += dtau;\n", ch[c]);
        o << fmt::format("                float acc = {};\n", zero);
        for (int i = kPsiAltitudeDegree; i >= 0; --i) {
            o << fmt::format("                {{ float row = {};\n", zero);
            for (int j = kPsiSunDegree; j >= 0; --j)
                o << fmt::format("                  row = row * py + {};\n",
                                 a[std::size_t(c * kPsiCoefficients + i * (kPsiSunDegree + 1) + j)]);
            o << "                  acc = acc * px + row; }\n";
        }
        o << fmt::format("                M_{} += w * {}(acc);\n", ch[c], exp_);
        o << "            }\n";
    }
    for (int e = 0; e < m.ext_count; ++e)
        o << fmt::format("            mp{0} = end{0};\n", e);
    o << "        }\n";
    o << "        }\n";
    o << "    }\n";
}

// I = Σ_k P_k(cos b0) A_k exp(R (x − 0.5)/0.45) per channel.
void emit_residual_decoding(std::ostringstream& o, const NeuralSky& net, const MlpHD& m, const Dialect& d,
                            const std::vector<std::string>& outputs, const MarchConstants& mc,
                            const Constant& constant) {
    const std::string zero = lit(0.0f, d), half = lit(0.5f, d);
    const std::string scale = lit(kResidualRange / (0.5f * kEncodeScale), d);
    o << "    // decoding: per phase term, the exact phase function times A as the network corrects it\n";
    o << fmt::format("    float cr = {0}, cg = {0}, cb = {0};\n", zero);
    const char* acc[] = {"cr", "cg", "cb"};
    const char* ch = "rgb";
    for (int k = 0; k < m.terms; ++k) {
        open_phase_term(o, net, m, k, d, constant);
        for (int c = 0; c < 3; ++c)
            o << fmt::format("        {} += p * A{}{} * {}({} * ({} - {}));\n", acc[c], k, ch[c], d.exp, scale,
                             outputs[std::size_t(3 * k + c)], half);
        o << "    }\n";
    }
    if (m.multiple && m.multiple_march) {
        emit_analytic_multiple(o, m, d, mc, constant);
        for (int c = 0; c < 3; ++c)
            o << fmt::format("    {} += M_{} * {}({} * ({} - {}));\n", acc[c], ch[c], d.exp, scale,
                             outputs[std::size_t(3 * m.terms + c)], half);
    } else if (m.multiple) {
        const std::string inv = lit(1.0f / kEncodeScale, d), off = lit(kEncodeOffset, d), one = lit(1.0f, d);
        o << "    { // the light scattered more than once, log-encoded per channel\n";
        for (int c = 0; c < 3; ++c) {
            const std::string mx = constant(m.multiple_max[c]);
            o << fmt::format("        float v{} = ({} - {}) * {};\n", c, outputs[std::size_t(3 * m.terms + c)], off,
                             inv);
            o << fmt::format("        {} += v{} > {} ? {} * {}({} * (v{} - {})) : {};\n", acc[c], c, zero, mx, d.exp,
                             lit(kMultipleLogRange, d), c, one, zero);
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
    if (m.family && !ubo)
        o << fmt::format("// aerosol: the amount of component \"{}\", a multiple of the atmosphere's, in [{:g}, {:g}].\n",
                         net.encoding.family_component, net.encoding.aerosol_min, net.encoding.aerosol_max);
    o << fmt::format("// Output: {} radiance per unit sun irradiance (1/sr), linear RGB; multiply by the\n",
                     net.atmosphere.scattering == Scattering::Single ? "single-scattered" : "total (single + multiple)");
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
        o << (m.output_kind == kOutputsResidual ? "#include <math.h>\n#include <stdbool.h>\n\n" : "#include <math.h>\n\n");
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
    if (m.output_kind == kOutputsResidual)
        o << residual_helpers(name, d, qual, hp);
    // An aerosol family takes its amount as a fifth argument, or from the uniform block.
    const std::string params = fmt::format("{0}float cos_view_zenith, {0}float cos_view_sun, {0}float cos_sun_zenith, "
                                           "{0}float density{1}",
                                           hp, m.family && !ubo ? fmt::format(", {}float aerosol", hp) : "");
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
    if (m.family) { // the last three values of the block (encoding_constants), or literals and the argument
        const std::size_t at = n_weights + encoding_constants(net).size() - 3;
        if (ubo)
            o << fmt::format("    float aerosol = {};\n", uniform(at + 2));
        o << fmt::format("    float in4 = {} * {}(aerosol) + {}; // the aerosol amount, -1 to 1 over its range\n",
                         ubo ? uniform(at) : lit(m.family_a, d), d.shader ? "log" : "logf",
                         ubo ? uniform(at + 1) : lit(m.family_b, d));
    }
    std::vector<std::string> out_names{"R", "G", "B", "M"};
    if (m.output_kind != kOutputsRadiance) {
        out_names.clear();
        for (const PhaseTerm& t : net.encoding.terms)
            for (const char* c : {"r", "g", "b"})
                out_names.push_back(fmt::format("S {} {}", t.component, c));
        if (m.multiple)
            for (const char* c : {"r", "g", "b"})
                out_names.push_back(fmt::format("multiple {}", c));
    }
    std::vector<std::string> outputs;
    for (int s = 0; s < lay.subnets; ++s) {
        const float* w = net.weights.data() + std::size_t(s) * std::size_t(lay.subnet_params);
        o << (lay.subnets == 1 ? std::string("    // shared network\n")
                               : fmt::format("    // sub-network {}\n", out_names[std::size_t(s)]));
        std::vector<std::string> prev{"in0", "in1", "in2", "in3"};
        if (m.family)
            prev.push_back("in4");
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
    if (m.output_kind == kOutputsResidual) {
        const MarchConstants mc = emit_analytic_terms(o, name, m, d, constant);
        emit_residual_decoding(o, net, m, d, outputs, mc, constant);
        o << "}\n";
        return o.str();
    }
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
