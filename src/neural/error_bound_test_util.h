// For tests: how far two evaluations of the same network may legitimately
// differ when they round differently (the CUDA kernels against the CPU, the
// batch inference against the scalar one).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "neural/internal.h"
#include "skybake/neural.h"

namespace skybake::neural_test {

// Fills the weights with fixed pseudo-random values in [−1.5, 1.5].
inline NeuralSky with_random_weights(NeuralSky net, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.5f, 1.5f);
    net.weights.resize(std::size_t(net.topology.weight_count()));
    for (float& w : net.weights)
        w = u(rng);
    net.validate();
    return net;
}

// A network with fixed pseudo-random weights (not trained: the evaluators
// must agree whatever the weights are).
inline NeuralSky random_network(const char* topology, unsigned seed) {
    NeuralSky net;
    net.topology = parse_topology(topology);
    net.atmosphere = atmosphere_preset("earth");
    net.encoding.max_n = 0.05;
    return with_random_weights(std::move(net), seed);
}

// The same network with other encodings: phase terms from its atmosphere's
// scattering components (maxima of a realistic size), and new pseudo-random
// weights when the output count changes the weight count. `multiple`:
// residual outputs of the atmosphere with multiple scattering, its term too.
inline NeuralSky with_encoding(NeuralSky net, InputEncoding inputs, OutputEncoding outputs, unsigned seed,
                               bool multiple = false) {
    net.encoding.inputs = inputs;
    net.encoding.outputs = outputs;
    net.encoding.brightness = BrightnessEncoding::Log;
    net.encoding.terms.clear();
    net.encoding.multiple = multiple;
    net.encoding.multiple_max = glm::dvec3(0.01, 0.02, 0.04);
    if (multiple)
        net.atmosphere.scattering = Scattering::Multiple;
    if (has_phase_terms(outputs))
        for (int k : neural::phase_term_components(net.atmosphere)) {
            const AtmosphereComponent& c = net.atmosphere.components[std::size_t(k)];
            net.encoding.terms.push_back({c.name, c.phase, c.phase_g, glm::dvec3(2.0, 4.0, 8.0) * double(k + 1)});
        }
    net.topology.outputs = net.encoding.output_count();
    return with_random_weights(std::move(net), seed);
}

// The same network with its multiple-scattering term marched
// (NeuralEncoding::multiple_psi): ln ψ of a realistic shape, from about e^-10
// at the lowest sun to e^-4 at noon and a little brighter high up, different
// per channel. Needs residual outputs with multiple scattering.
inline NeuralSky with_marched_multiple(NeuralSky net) {
    net.encoding.multiple_psi.assign(std::size_t(3 * neural::kPsiCoefficients), 0.0);
    net.encoding.multiple_psi_mu_min = -0.5;
    for (int c = 0; c < 3; ++c) {
        double* a = net.encoding.multiple_psi.data() + c * neural::kPsiCoefficients;
        const int row = neural::kPsiSunDegree + 1; // a[i * row + j]: x^i y^j
        a[0] = std::log(0.02 * (1.0 + 0.3 * c));
        a[1] = 4.0 - 0.2 * c;
        a[2] = -2.0;
        a[3] = 0.3;
        a[row] = 0.2;
        a[row + 1] = -0.1 * c;
        a[2 * row] = -0.05;
    }
    return net;
}

// The same network as one of an aerosol family (its "mie" amount from lo to
// hi, a fifth input), evaluated at `aerosol`, with new pseudo-random weights.
// Needs residual outputs of single scattering.
inline NeuralSky with_family(NeuralSky net, double lo, double hi, double aerosol, unsigned seed) {
    net.encoding.family_component = "mie";
    net.encoding.aerosol_min = lo;
    net.encoding.aerosol_max = hi;
    net.topology.inputs = net.encoding.input_count();
    net.aerosol = aerosol;
    return with_random_weights(std::move(net), seed);
}

// A model of how far the encoded outputs move when every product-sum and
// every activation rounds differently on the two sides (the GPU's fmaf,
// ex2.approx and rcp.approx, or expf, against the CPU's summation order and
// Eigen's exp). Rounding errors are taken as independent, so they add in
// quadrature (a worst-case sum is thousands of times larger than what is
// measured on wide layers). Per neuron of layer l + 1, with activations and
// inputs in [−1, 1]:
//   e = |f'|max · sqrt(Σ_c w_c² e_c² + (n + 1) u² (Σ_c w_c² + b²)) + 4u,
// |f'|max = ln 2 / 2 (f(x) = σ(−2 ln 2 · x)), u = 2⁻²⁴, and 4u for the
// activation's own error (ex2.approx 2 ulp, rcp.approx 1 ulp). Returns the
// model for each encoded output; check_modelled_bound allows kSigmas times it.
constexpr double kSigmas = 8.0;

inline std::vector<double> encoded_error_bound(const NeuralSky& net) {
    const neural::MlpHD m = neural::make_mlp_hd(net);
    const double u = std::ldexp(1.0, -24), slope = std::log(2.0) / 2.0;
    std::vector<double> bound(std::size_t(net.encoding.output_count()), 0.0);
    for (int sub = 0; sub < m.subnets; ++sub) {
        const float* w = net.weights.data() + std::size_t(sub) * std::size_t(m.subnet_params);
        std::vector<double> e(std::size_t(m.width[0]), 0.0);
        for (int l = 0; l < m.layers; ++l) {
            const int n_in = m.width[l], n_out = m.width[l + 1];
            std::vector<double> next(static_cast<std::size_t>(n_out));
            for (int r = 0; r < n_out; ++r) {
                const double b = w[n_out * n_in + r];
                double propagated = 0.0, w2 = b * b;
                for (int c = 0; c < n_in; ++c) {
                    const double wc = w[r * n_in + c];
                    propagated += wc * wc * e[std::size_t(c)] * e[std::size_t(c)];
                    w2 += wc * wc;
                }
                next[std::size_t(r)] = slope * std::sqrt(propagated + (n_in + 1) * u * u * w2) + 4.0 * u;
            }
            e = std::move(next);
            w += n_out * n_in + n_out;
        }
        for (std::size_t k = 0; k < e.size(); ++k)
            bound[std::size_t(sub) + k] = e[k];
    }
    return bound;
}

// GPU against CPU on lit samples. Metric: per sample, the largest channel
// difference over the CPU's largest channel. Each sample's difference must lie
// within kSigmas times its model, decoded from encoded_error_bound(): channel
// errors e_c / (0.9 c_max) plus the brightness's relative error,
// log_range · e_M / 0.9 for the log encoding, e_M / (0.9 M) for the seed's
// linear one. For the seed's topology that is about 1e-4; the CPU's batch and
// scalar passes use 3% of it, and a GPU's difference is estimated at
// 3.5–4e-5. Samples whose brightness output is within e_M of the
// night threshold (0.05) may decode as night on one side only and are left
// out; at least a tenth of the samples must be lit. Phase-factored outputs:
// every channel of every S_k is log-encoded, a sum of positive terms is off
// by at most its worst term's relative error, log_range · e_k / 0.9 (+ the
// decoder's exp and the phase function's float rounding), and samples with
// any code within e_k of 0.05 are left out.
struct BoundCheck {
    std::size_t lit = 0, outside = 0; // compared samples, and those outside their bound
    double worst_error = 0.0, worst_fraction = 0.0;
};

inline BoundCheck check_modelled_bound(const NeuralSky& net, const std::vector<SkySample>& samples,
                                       const std::vector<glm::vec3>& cpu, const std::vector<glm::vec3>& gpu) {
    const std::vector<double> e = encoded_error_bound(net);
    const bool factored = net.encoding.outputs == OutputEncoding::PhaseFactored;
    const double e_c = factored ? 0.0 : std::max({e[0], e[1], e[2]});
    const double e_max = *std::max_element(e.begin(), e.end());
    BoundCheck r;
    for (std::size_t i = 0; i < cpu.size(); ++i) {
        float enc[neural::kMaxOutputs];
        neural_sky_encoded(net, samples[i], enc);
        if (std::max({cpu[i].x, cpu[i].y, cpu[i].z}) <= 0.0f)
            continue;
        bool near_threshold = false;
        for (std::size_t k = factored ? 0 : 3; k < e.size(); ++k)
            near_threshold |= std::abs(double(enc[k]) - 0.05) <= e[k];
        if (near_threshold)
            continue;
        ++r.lit;
        double bound;
        if (factored) {
            bound = kSigmas * (std::expm1(net.encoding.log_range * e_max / 0.9) + 1e-6) + 1e-6;
        } else {
            const double m = (double(enc[3]) - 0.05) / 0.9;
            const double c_max = std::max({enc[0], enc[1], enc[2]}) - 0.05;
            const double dn = net.encoding.brightness == BrightnessEncoding::Log
                                  ? std::expm1(net.encoding.log_range * e[3] / 0.9) + 1e-6 // + the decoder's exp
                                  : e[3] / (0.9 * m);
            bound = kSigmas * (e_c / std::max(0.9 * c_max, 1e-30) + dn);
        }
        const double ref = std::max({cpu[i].x, cpu[i].y, cpu[i].z});
        double err = 0.0;
        for (int c = 0; c < 3; ++c)
            err = std::max(err, std::abs(double(gpu[i][c]) - double(cpu[i][c])) / ref);
        r.worst_error = std::max(r.worst_error, err);
        r.worst_fraction = std::max(r.worst_fraction, err / bound);
        r.outside += err > bound;
    }
    return r;
}

inline void expect_within_modelled_bound(const NeuralSky& net, const std::vector<SkySample>& samples,
                                         const std::vector<glm::vec3>& cpu, const std::vector<glm::vec3>& gpu) {
    const BoundCheck r = check_modelled_bound(net, samples, cpu, gpu);
    std::printf("%zu lit samples of %zu: worst relative difference %.2e, %.3f of its modelled bound\n", r.lit,
                cpu.size(), r.worst_error, r.worst_fraction);
    EXPECT_GE(r.lit, cpu.size() / 10) << "too few lit samples to compare";
    EXPECT_EQ(r.outside, 0u) << "samples outside their modelled bound";
}

} // namespace skybake::neural_test
