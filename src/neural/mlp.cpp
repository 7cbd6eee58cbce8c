// Batched forward and backward passes of the seed's perceptron (Pietras &
// Rudnicki, seed 000, section III) with Eigen: one sample per column, one
// matrix product per layer, the activation f(x) = 1/(1 + 2^(2x)) vectorised.
// Also the output encoding of section III and the CPU batch inference.
#include <algorithm>
#include <cassert>
#include <cmath>

#include <fmt/format.h>

#include "core/parallel.h"
#include "neural/internal.h"
#include "skybake/error.h"

namespace skybake {

using namespace neural;

namespace neural {

namespace {

using RowMap = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

// a = f(W in + b), in place over z.
void layer_forward(const LayerLayout& L, const float* w, const Eigen::Ref<const MatF>& in, MatF& a) {
    const RowMap W(w + L.w_offset, L.out, L.in);
    const Eigen::Map<const Eigen::VectorXf> b(w + L.b_offset, L.out);
    a.resize(L.out, in.cols());
    a.noalias() = W * in;
    a.colwise() += b;
    a = (1.0f + (a.array() * kSlope).exp()).inverse().matrix();
}

// f'(z) expressed by the output a = f(z): −kSlope a (1 − a).
auto activation_slope(const MatF& a) { return (-kSlope) * a.array() * (1.0f - a.array()); }

} // namespace

Layout make_layout(const NeuralTopology& topology) {
    Layout lay;
    lay.subnets = topology.subnet_count();
    lay.outputs = topology.outputs_per_subnet();
    std::vector<int> widths{topology.inputs};
    widths.insert(widths.end(), topology.hidden.begin(), topology.hidden.end());
    widths.push_back(lay.outputs);
    int off = 0;
    for (std::size_t l = 0; l + 1 < widths.size(); ++l) {
        LayerLayout L;
        L.in = widths[l];
        L.out = widths[l + 1];
        L.w_offset = off;
        off += L.in * L.out;
        L.b_offset = off;
        off += L.out;
        lay.layers.push_back(L);
    }
    lay.subnet_params = off;
    return lay;
}

MlpHD make_mlp_hd(const NeuralSky& net) {
    const Layout lay = make_layout(net.topology);
    assert(int(lay.layers.size()) <= kMaxLayers);
    MlpHD m;
    m.weights = net.weights.data();
    m.subnets = lay.subnets;
    m.layers = int(lay.layers.size());
    m.width[0] = net.topology.inputs;
    for (int l = 0; l < m.layers; ++l)
        m.width[l + 1] = lay.layers[std::size_t(l)].out;
    m.subnet_params = lay.subnet_params;
    m.outputs = net.topology.outputs;
    set_encoding_hd(net.encoding, net.atmosphere, m);
    m.aerosol = float(net.aerosol);
    return m;
}

void set_encoding_hd(const NeuralEncoding& e, const Atmosphere& atmosphere, MlpHD& m) {
    m.brightness = e.brightness == BrightnessEncoding::Linear ? kBrightnessLinear : kBrightnessLog;
    m.max_n = float(e.max_n);
    m.log_range = float(e.log_range);
    m.inputs = e.inputs == InputEncoding::Horizon ? kInputsHorizon : kInputsSeed;
    m.R0 = float(atmosphere.planet_radius_km);
    m.Rtop = float(atmosphere.top_radius_km);
    m.scale_height = atmosphere.components.empty() ? 8.0f : float(atmosphere.components[0].scale_height_km);
    m.output_kind = e.outputs == OutputEncoding::Residual        ? kOutputsResidual
                    : e.outputs == OutputEncoding::PhaseFactored ? kOutputsPhaseFactored
                                                                 : kOutputsRadiance;
    m.terms = has_phase_terms(e.outputs) ? int(std::min<std::size_t>(e.terms.size(), kMaxTerms)) : 0;
    for (int k = 0; k < m.terms; ++k) {
        const PhaseTerm& t = e.terms[std::size_t(k)];
        m.term_phase[k] = int(t.phase);
        m.term_g[k] = float(t.g);
        for (int c = 0; c < 3; ++c)
            m.term_max[k][c] = float(t.max_s[c]);
    }
    if (e.outputs != OutputEncoding::Residual)
        return;
    m.multiple = e.multiple ? 1 : 0;
    for (int c = 0; c < 3; ++c)
        m.multiple_max[c] = float(e.multiple_max[c]);
    m.multiple_march = e.multiple && e.multiple_marched() ? 1 : 0;
    if (m.multiple_march) {
        m.psi_mu_min = float(e.multiple_psi_mu_min);
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < kPsiCoefficients; ++i)
                m.psi[c][i] = float(e.multiple_psi[std::size_t(c * kPsiCoefficients + i)]);
    }
    // The analytic march's atmosphere (check_residual_atmosphere has checked it fits).
    m.ext_count = 0;
    for (const AtmosphereComponent& c : atmosphere.components)
        if (c.profile == DensityProfile::Exponential && m.ext_count < kMaxTerms) {
            m.ext_height[m.ext_count] = float(c.scale_height_km);
            for (int ch = 0; ch < 3; ++ch)
                m.ext_beta[m.ext_count][ch] = float(c.extinction_per_km[ch]);
            for (int k = 0; k < m.terms; ++k)
                if (e.terms[std::size_t(k)].component == c.name) {
                    m.term_ext[k] = m.ext_count;
                    for (int ch = 0; ch < 3; ++ch)
                        m.term_beta[k][ch] = float(c.scattering_per_km[ch]);
                }
            ++m.ext_count;
        }
    if (!e.has_family())
        return;
    m.family = 1;
    for (int k = 0; k < m.terms; ++k)
        if (e.terms[std::size_t(k)].component == e.family_component) {
            m.family_term = k;
            m.family_ext = m.term_ext[k];
        }
    // in4 = a ln(aerosol) + b: −1 at aerosol_min, +1 at aerosol_max.
    const double lo = std::log(e.aerosol_min), hi = std::log(e.aerosol_max);
    m.family_a = float(2.0 / (hi - lo));
    m.family_b = float(-(hi + lo) / (hi - lo));
}

void check_family(const NeuralEncoding& e, const Atmosphere& atmosphere, const std::string& where) {
    if (e.outputs != OutputEncoding::Residual || e.multiple)
        throw Error("an aerosol family needs residual outputs of single scattering (its analytic march scales the "
                    "aerosol); multiple scattering is not supported in a family",
                    where);
    if (std::none_of(e.terms.begin(), e.terms.end(), [&](const PhaseTerm& t) { return t.component == e.family_component; }))
        throw Error(fmt::format("the family's component '{}' is not a scattering component of atmosphere '{}'",
                                e.family_component, atmosphere.name),
                    where);
    if (!(std::isfinite(e.aerosol_min) && std::isfinite(e.aerosol_max) && e.aerosol_min > 0.0 &&
          e.aerosol_max > e.aerosol_min * 1.001 && e.aerosol_max <= e.aerosol_min * 1e4))
        throw Error(fmt::format("the aerosol range [{}, {}] must be positive, increasing and span at most 1e4",
                                e.aerosol_min, e.aerosol_max),
                    where);
}

void check_residual_atmosphere(const NeuralEncoding& e, const Atmosphere& atmosphere, const std::string& where) {
    if ((atmosphere.scattering != Scattering::Single) != e.multiple)
        throw Error(e.multiple ? "a multiple-scattering term needs an atmosphere with multiple scattering"
                               : "residual outputs of an atmosphere with multiple scattering need its term "
                                 "(encoding.multiple_max)",
                    where + ": encoding.multiple_max");
    int exponential = 0;
    for (const AtmosphereComponent& c : atmosphere.components)
        exponential += c.profile == DensityProfile::Exponential ? 1 : 0;
    if (exponential > kMaxTerms)
        throw Error(fmt::format("residual outputs take at most {} exponential components, not {}", kMaxTerms,
                                exponential),
                    where + ": atmosphere.components");
    for (const PhaseTerm& t : e.terms) {
        const auto c = std::find_if(atmosphere.components.begin(), atmosphere.components.end(),
                                    [&](const AtmosphereComponent& a) { return a.name == t.component; });
        if (c == atmosphere.components.end() || c->profile != DensityProfile::Exponential)
            throw Error(fmt::format("residual outputs need each scattering component to be exponential; '{}' is "
                                    "not, or is missing from the atmosphere",
                                    t.component),
                        where + ": encoding.terms");
    }
}

std::vector<int> phase_term_components(const Atmosphere& atmosphere) {
    std::vector<int> k;
    for (std::size_t i = 0; i < atmosphere.components.size(); ++i) {
        const AtmosphereComponent& c = atmosphere.components[i];
        if (c.phase != PhaseFunction::None && std::max({c.scattering_per_km.x, c.scattering_per_km.y,
                                                        c.scattering_per_km.z}) > 0.0)
            k.push_back(int(i));
    }
    return k;
}

void forward_subnet(const Layout& layout, const float* w, const Eigen::Ref<const MatF>& x, Workspace& ws) {
    ws.a.resize(layout.layers.size());
    for (std::size_t l = 0; l < layout.layers.size(); ++l) {
        if (l == 0)
            layer_forward(layout.layers[l], w, x, ws.a[l]);
        else
            layer_forward(layout.layers[l], w, ws.a[l - 1], ws.a[l]);
    }
}

void forward_network(const Layout& layout, const float* weights, const Eigen::Ref<const MatF>& x,
                     Eigen::Ref<MatF> out, Workspace& ws) {
    for (int s = 0; s < layout.subnets; ++s) {
        forward_subnet(layout, weights + std::size_t(s) * std::size_t(layout.subnet_params), x, ws);
        out.middleRows(s * layout.outputs, layout.outputs) = ws.a.back();
    }
}

double subnet_loss_grad(const Layout& layout, const float* weights, int s, const Eigen::Ref<const MatF>& x,
                        const Eigen::Ref<const MatF>& t, const Eigen::Ref<const MatF>& mask, double* grad,
                        Workspace& ws) {
    const float* w = weights + std::size_t(s) * std::size_t(layout.subnet_params);
    forward_subnet(layout, w, x, ws);
    const int nl = int(layout.layers.size());
    const int row = s * layout.outputs;
    const MatF& y = ws.a.back();
    ws.delta.resize(std::size_t(nl));
    MatF& d_out = ws.delta[std::size_t(nl - 1)];
    d_out = (mask.middleRows(row, layout.outputs).array() * (y.array() - t.middleRows(row, layout.outputs).array()))
                .matrix();
    const double loss = double(d_out.squaredNorm());
    if (!grad)
        return loss;
    d_out.array() *= activation_slope(y);
    for (int l = nl - 1; l >= 0; --l) {
        const LayerLayout& L = layout.layers[std::size_t(l)];
        const MatF& d = ws.delta[std::size_t(l)];
        const Eigen::Ref<const MatF> in = l == 0 ? x : Eigen::Ref<const MatF>(ws.a[std::size_t(l - 1)]);
        const MatF g = d * in.transpose(); // out × in
        for (int r = 0; r < L.out; ++r)
            for (int c = 0; c < L.in; ++c)
                grad[L.w_offset + r * L.in + c] += double(g(r, c));
        const Eigen::VectorXf gb = d.rowwise().sum();
        for (int r = 0; r < L.out; ++r)
            grad[L.b_offset + r] += double(gb(r));
        if (l > 0) {
            const RowMap W(w + L.w_offset, L.out, L.in);
            MatF& dp = ws.delta[std::size_t(l - 1)];
            dp.noalias() = W.transpose() * d;
            dp.array() *= activation_slope(ws.a[std::size_t(l - 1)]);
        }
    }
    return loss;
}

double subnet_normal_equations(const Layout& layout, const float* weights, int s, const Eigen::Ref<const MatF>& x,
                               const Eigen::Ref<const MatF>& t, const Eigen::Ref<const MatF>& mask,
                               Eigen::MatrixXf& jtj, Eigen::VectorXf& jtr, Workspace& ws) {
    const float* w = weights + std::size_t(s) * std::size_t(layout.subnet_params);
    forward_subnet(layout, w, x, ws);
    const int nl = int(layout.layers.size());
    const Eigen::Index B = x.cols();
    const int P = layout.subnet_params;
    const MatF& y = ws.a.back();
    const MatF slope_out = activation_slope(y).matrix();
    ws.delta.resize(std::size_t(nl));
    MatF J(B, P);
    double loss = 0.0;
    for (int o = 0; o < layout.outputs; ++o) {
        const int row = s * layout.outputs + o;
        const Eigen::VectorXf m = mask.row(row).transpose();
        const Eigen::VectorXf r = (m.array() * (y.row(o).transpose().array() - t.row(row).transpose().array())).matrix();
        loss += double(r.squaredNorm());
        MatF& d_out = ws.delta[std::size_t(nl - 1)];
        d_out.setZero(layout.outputs, B);
        d_out.row(o) = (m.transpose().array() * slope_out.row(o).array()).matrix();
        for (int l = nl - 1; l >= 0; --l) {
            const LayerLayout& L = layout.layers[std::size_t(l)];
            const MatF& d = ws.delta[std::size_t(l)];
            const Eigen::Ref<const MatF> in = l == 0 ? x : Eigen::Ref<const MatF>(ws.a[std::size_t(l - 1)]);
            for (int rr = 0; rr < L.out; ++rr) {
                for (int c = 0; c < L.in; ++c)
                    J.col(L.w_offset + rr * L.in + c) = (d.row(rr).array() * in.row(c).array()).transpose();
                J.col(L.b_offset + rr) = d.row(rr).transpose();
            }
            if (l > 0) {
                const RowMap W(w + L.w_offset, L.out, L.in);
                MatF& dp = ws.delta[std::size_t(l - 1)];
                dp.noalias() = W.transpose() * d;
                dp.array() *= activation_slope(ws.a[std::size_t(l - 1)]);
            }
        }
        jtj.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
        jtr.noalias() += J.transpose() * r;
    }
    return loss;
}

void encode_targets(const NeuralEncoding& encoding, std::span<const glm::vec3> radiance, MatF& targets, MatF& mask) {
    const Eigen::Index n = Eigen::Index(radiance.size());
    targets.resize(4, n);
    mask.resize(4, n);
    parallel_for(radiance.size(), 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            float enc[4];
            encode_sky_radiance(encoding, radiance[i], enc); // radiance outputs
            const bool night = !(std::max({radiance[i].x, radiance[i].y, radiance[i].z}) > 0.0f);
            for (int k = 0; k < 4; ++k) {
                targets(k, Eigen::Index(i)) = enc[k];
                mask(k, Eigen::Index(i)) = night && k < 3 ? 0.0f : 1.0f;
            }
        }
    });
}

void encode_split_targets(const NeuralEncoding& encoding, std::span<const glm::vec3> split, std::size_t components,
                          const std::vector<int>& term_components, MatF& targets, MatF& mask) {
    const std::size_t n = split.size() / components;
    const int outputs = 3 * int(term_components.size());
    targets.resize(outputs, Eigen::Index(n));
    mask.setOnes(outputs, Eigen::Index(n));
    parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            for (std::size_t k = 0; k < term_components.size(); ++k) {
                const glm::vec3 v = split[i * components + std::size_t(term_components[k])];
                for (int c = 0; c < 3; ++c)
                    targets(Eigen::Index(3 * k + std::size_t(c)), Eigen::Index(i)) =
                        encode_log(double(v[c]), encoding.terms[k].max_s[c], encoding.log_range);
            }
    });
}

void encode_residual_targets(std::span<const glm::vec3> split, std::size_t components,
                             const std::vector<int>& term_components, const MatF& base, MatF& targets, MatF& mask) {
    const std::size_t n = split.size() / components;
    const int outputs = 3 * int(term_components.size());
    targets.resize(outputs, Eigen::Index(n));
    mask.resize(outputs, Eigen::Index(n));
    parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            for (std::size_t k = 0; k < term_components.size(); ++k) {
                const glm::vec3 v = split[i * components + std::size_t(term_components[k])];
                for (int c = 0; c < 3; ++c) {
                    const Eigen::Index row = Eigen::Index(3 * k + std::size_t(c));
                    const double s = double(v[c]), a = double(base(row, Eigen::Index(i)));
                    const bool lit = s > 0.0 && a > 0.0;
                    const double x = lit ? std::clamp(std::log(s / a) / double(kResidualRange), -1.0, 1.0) : 0.0;
                    targets(row, Eigen::Index(i)) = float(0.5 + 0.5 * double(kEncodeScale) * x);
                    mask(row, Eigen::Index(i)) = lit ? 1.0f : 0.0f;
                }
            }
    });
}

MatF analytic_matrix(const MlpHD& m, std::span<const SkySample> samples, std::span<const float> aerosol) {
    MatF a(3 * m.terms + (m.multiple && m.multiple_march ? 3 : 0), Eigen::Index(samples.size()));
    parallel_for(samples.size(), 4096, [&](std::size_t b, std::size_t e) {
        float base[kMaxOutputs];
        MlpHD at = m;
        for (std::size_t i = b; i < e; ++i) {
            const SkySample& s = samples[i];
            if (!aerosol.empty())
                at.aerosol = aerosol[i];
            analytic_base(at, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density, base);
            for (int k = 0; k < int(a.rows()); ++k)
                a(k, Eigen::Index(i)) = base[k];
        }
    });
    return a;
}

float encode_log(double value, double max, double log_range) {
    if (!(value > 0.0))
        return 0.0f; // no light: below the offset, decoded as 0
    const double m = std::max(0.0, 1.0 + std::log(value / max) / log_range);
    return float(kEncodeOffset + kEncodeScale * std::min(m, 1.0));
}

MatF samples_to_matrix(const MlpHD& m, std::span<const SkySample> samples, std::span<const float> aerosol) {
    MatF x(m.width[0], Eigen::Index(samples.size()));
    MlpHD at = m;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const SkySample& s = samples[i];
        if (!aerosol.empty())
            at.aerosol = aerosol[i];
        float in[kMaxInputs];
        encode_inputs(at, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density, in);
        for (int k = 0; k < m.width[0]; ++k)
            x(k, Eigen::Index(i)) = in[k];
    }
    return x;
}

} // namespace neural

void encode_sky_radiance(const NeuralEncoding& e, const glm::vec3& c, float enc[4]) {
    const float n = std::max({c.x, c.y, c.z});
    if (!(n > 0.0f)) { // night: M = 0; R, G, B are not trained (mask)
        enc[0] = enc[1] = enc[2] = enc[3] = 0.0f;
        return;
    }
    enc[0] = kEncodeOffset + kEncodeScale * std::max(0.0f, c.x) / n;
    enc[1] = kEncodeOffset + kEncodeScale * std::max(0.0f, c.y) / n;
    enc[2] = kEncodeOffset + kEncodeScale * std::max(0.0f, c.z) / n;
    if (e.brightness == BrightnessEncoding::Linear)
        enc[3] = float(kEncodeOffset + kEncodeScale * std::min(double(n) / e.max_n, 1.0));
    else
        enc[3] = encode_log(double(n), e.max_n, e.log_range);
}

glm::vec3 decode_sky_radiance(const NeuralEncoding& e, const float enc[4]) {
    MlpHD m;
    NeuralEncoding radiance = e;
    radiance.outputs = OutputEncoding::Radiance;
    set_encoding_hd(radiance, Atmosphere{}, m);
    return decode_sky(m, enc);
}

void evaluate_neural_sky(const NeuralSky& net, std::span<const SkySample> samples, std::span<glm::vec3> out) {
    evaluate_neural_sky_at(net, samples, {}, out);
}

void neural::evaluate_neural_sky_at(const NeuralSky& net, std::span<const SkySample> samples,
                                    std::span<const float> aerosol, std::span<glm::vec3> out) {
    assert(samples.size() == out.size());
    assert(aerosol.empty() || aerosol.size() == samples.size());
    assert(net.weights.size() == std::size_t(net.topology.weight_count()));
    const Layout layout = make_layout(net.topology);
    const MlpHD hd0 = make_mlp_hd(net);
    constexpr std::size_t kBlock = 1024;
    const std::size_t blocks = (samples.size() + kBlock - 1) / kBlock;
    parallel_for(blocks, 1, [&](std::size_t b0, std::size_t b1) {
        Workspace ws;
        MatF enc(hd0.outputs, Eigen::Index(kBlock));
        for (std::size_t b = b0; b < b1; ++b) {
            const std::size_t lo = b * kBlock, hi = std::min(samples.size(), lo + kBlock);
            const MatF x = samples_to_matrix(hd0, samples.subspan(lo, hi - lo),
                                             aerosol.empty() ? aerosol : aerosol.subspan(lo, hi - lo));
            enc.resize(hd0.outputs, x.cols());
            forward_network(layout, net.weights.data(), x, enc, ws);
            float base[kMaxOutputs];
            MlpHD hd = hd0;
            for (std::size_t i = lo; i < hi; ++i) {
                const SkySample& s = samples[i];
                if (!aerosol.empty())
                    hd.aerosol = aerosol[i];
                assert(is_valid_sky_sample(s, 1e-4));
                if (hd.output_kind == kOutputsResidual)
                    analytic_base(hd, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density, base);
                out[i] = decode_sky(hd, enc.col(Eigen::Index(i - lo)).data(), s.cos_view_sun, base);
            }
        }
    });
}

glm::vec3 neural_sky_radiance(const NeuralSky& net, const SkySample& s) {
    const MlpHD hd = make_mlp_hd(net);
    return neural_sky(hd, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density);
}

void neural_sky_encoded(const NeuralSky& net, const SkySample& s, float* enc) {
    const MlpHD hd = make_mlp_hd(net);
    float in[kMaxInputs];
    encode_inputs(hd, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density, in);
    mlp_forward(hd, in, enc);
}

} // namespace skybake
