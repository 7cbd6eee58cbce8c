// Training of the neural sky on the CPU (Pietras & Rudnicki, seed 000,
// section III: random uniform samples of the sky function, 800,000 of them).
//
// Kingma D. P., Ba J. Adam: A Method for Stochastic Optimization. ICLR 2015.
// Marquardt D. W. An Algorithm for Least-Squares Estimation of Nonlinear
// Parameters. SIAM J. Appl. Math. 11(2), 1963.
//
// Adam on shuffled mini-batches with an exponentially decaying step, then
// Levenberg–Marquardt on each sub-network: the sub-networks of the seed's
// topology are independent (81 parameters each), so their normal equations
// are small and dense. Every reduction is cut into fixed chunks and summed in
// chunk order, so the result does not depend on the thread count.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <optional>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <glm/vec2.hpp>
#include <fmt/format.h>

#include "core/parallel.h"
#include "core/progress.h"
#include "neural/internal.h"
#include "skybake/core.h"
#include "core/random.h"
#include "skybake/error.h"
#include "sky/device.h"

namespace skybake {

using namespace neural;

namespace {

using SplitMix = SplitMix64;


using DataSet = TrainingData;

// Training targets from the sky model's table path, on the CPU or the GPU.
void sky_targets(const SkyModel& model, std::span<const SkySample> s, std::span<glm::vec3> out, Device device) {
    if (device == Device::Cuda)
        evaluate_sky_cuda(model, s, out);
    else
        evaluate_sky(model, s, out, SkyMethod::Tables);
}

// The phase-free parts S_k of the table path (n × components) and the radiance Σ_k P_k S_k they make.
void split_targets(const SkyModel& model, std::span<const SkySample> s, std::vector<glm::vec3>& split,
                   std::vector<glm::vec3>& radiance) {
    scaled_sky_targets(model, s, {}, -1, split, radiance);
}

} // namespace

void neural::scaled_sky_targets(const SkyModel& model, std::span<const SkySample> s, std::span<const float> aerosol,
                                int family, std::vector<glm::vec3>& split, std::vector<glm::vec3>& radiance) {
    const Atmosphere& atm = model.atmosphere();
    const std::size_t nc = atm.components.size();
    split.resize(s.size() * nc);
    sky::evaluate_sky_split(model, s, split, aerosol, family);
    radiance.resize(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        glm::dvec3 c(0.0);
        for (std::size_t k = 0; k < nc; ++k)
            c += phase_function(atm.components[k].phase, atm.components[k].phase_g, double(s[i].cos_view_sun)) *
                 glm::dvec3(split[i * nc + k]);
        radiance[i] = glm::vec3(c);
    }
}

Atmosphere neural::scaled_atmosphere(const NeuralEncoding& family, const Atmosphere& atmosphere, double aerosol) {
    Atmosphere a = atmosphere;
    for (AtmosphereComponent& c : a.components)
        if (c.name == family.family_component) {
            // As evaluate_sky_split scales the float coefficients (×1 is exact).
            c.scattering_per_km *= aerosol;
            c.extinction_per_km *= aerosol;
        }
    return a;
}

std::vector<float> neural::draw_aerosol(const NeuralEncoding& enc, std::size_t n, std::uint64_t seed) {
    // Log-uniform over [aerosol_min, aerosol_max], from its own stream of the samples' seed.
    SplitMix rng{seed ^ 0xae505015ae505015ull};
    const double lo = std::log(enc.aerosol_min), hi = std::log(enc.aerosol_max);
    std::vector<float> a(n);
    for (float& v : a)
        v = float(std::exp(lo + (hi - lo) * rng.uniform()));
    return a;
}

int neural::family_component_index(const NeuralEncoding& enc, const Atmosphere& atmosphere) {
    for (std::size_t k = 0; k < atmosphere.components.size(); ++k)
        if (atmosphere.components[k].name == enc.family_component)
            return int(k);
    return -1;
}

std::vector<SkySample> neural::draw_hard_samples(std::size_t n, std::uint64_t seed, const Atmosphere& atm) {
    const double pi = 3.14159265358979323846, R0 = atm.planet_radius_km;
    std::vector<SkySample> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        SplitMix rng{seed * 0xD1B54A32D192ED03ull + i * 0x9E3779B97F4A7C15ull + 0x4a4dull};
        rng.next();
        for (;;) {
            const double rho = 1.0 - rng.uniform(); // (0, 1], as the uniform samples
            const double r = R0 + atm.altitude_from_density(rho);
            const double mu_h = -std::sqrt(std::max(0.0, 1.0 - (R0 / r) * (R0 / r)));
            double mu = 0.0, mu_s = 0.0, nu = 0.0;
            auto around = [&](double phi) { // ν from the two zenith cosines and the azimuth between them
                return mu * mu_s + std::sqrt(std::max(0.0, (1.0 - mu * mu) * (1.0 - mu_s * mu_s))) * std::cos(phi);
            };
            switch (i % 3) {
            case 0: // the horizon: within sin 2° in cosine of the geometric horizon, the sun above −20°
                mu = std::clamp(mu_h + std::sin(2.0 * pi / 180.0) * (2.0 * rng.uniform() - 1.0), -1.0, 1.0);
                mu_s = std::sin((-20.0 + 110.0 * rng.uniform()) * pi / 180.0);
                nu = around(2.0 * pi * rng.uniform());
                break;
            case 1: { // the aureole: within 15° of the sun, uniform in solid angle
                mu_s = std::sin((-10.0 + 100.0 * rng.uniform()) * pi / 180.0);
                const double cg = 1.0 - (1.0 - std::cos(15.0 * pi / 180.0)) * rng.uniform();
                const double sg = std::sqrt(std::max(0.0, 1.0 - cg * cg)), psi = 2.0 * pi * rng.uniform();
                const double ss = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
                // the sun (ss, 0, μs); e1 = (−μs, 0, ss), e2 = (0, 1, 0)
                mu = cg * mu_s + sg * std::cos(psi) * ss;
                nu = cg;
                break;
            }
            default: // the terminator: the sun from −15° to 5°, any view
                mu = 2.0 * rng.uniform() - 1.0;
                mu_s = std::sin((-15.0 + 20.0 * rng.uniform()) * pi / 180.0);
                nu = around(2.0 * pi * rng.uniform());
                break;
            }
            const SkySample x{float(mu), float(std::clamp(nu, -1.0, 1.0)), float(mu_s), float(rho)};
            if (is_valid_sky_sample(x, 0.0)) {
                out[i] = x;
                break;
            }
        }
    }
    return out;
}

TrainingData neural::make_training_data(const SkyModel& model, const NeuralEncoding& enc, std::size_t n,
                                        std::uint64_t seed, Device device, double hard_share,
                                        double flight_share) {
    DataSet d;
    std::vector<SkySample> s = draw_sky_samples(n, seed);
    // A share of the samples replaced by others, spread evenly: every k-th.
    const auto replace_share = [&](double share, auto draw) {
        const std::size_t k = std::size_t(std::llround(share * double(n)));
        const std::vector<SkySample> other = draw(k);
        for (std::size_t j = 0; j < k; ++j)
            s[std::min(n - 1, std::size_t(double(j) / share))] = other[j];
    };
    if (hard_share > 0.0) // where the sky is hard
        replace_share(hard_share, [&](std::size_t k) { return draw_hard_samples(k, seed ^ 0x4a4d4a4dull, model.atmosphere()); });
    if (flight_share > 0.0) // then a flight's (draw_flight_samples)
        replace_share(flight_share,
                      [&](std::size_t k) { return draw_flight_samples(k, seed ^ 0x5151f11eull, model.atmosphere()); });
    MlpHD hd;
    set_encoding_hd(enc, model.atmosphere(), hd);
    hd.width[0] = enc.input_count();
    int family = -1;
    if (enc.has_family()) {
        d.aerosol = draw_aerosol(enc, n, seed);
        family = family_component_index(enc, model.atmosphere());
    }
    d.x = samples_to_matrix(hd, s, d.aerosol);
    if (enc.outputs == OutputEncoding::Residual) {
        std::vector<glm::vec3> split;
        scaled_sky_targets(model, s, d.aerosol, family, split, d.radiance);
        d.base = analytic_matrix(hd, s, d.aerosol);
        encode_residual_targets(split, model.atmosphere().components.size(),
                                phase_term_components(model.atmosphere()), d.base, d.t, d.mask);
        if (enc.multiple) {
            // Three more rows: the total less the single scattering, log-encoded.
            std::vector<glm::vec3> total(n);
            sky_targets(model, s, total, device);
            const Eigen::Index rows = d.t.rows();
            d.t.conservativeResize(rows + 3, Eigen::NoChange);
            d.mask.conservativeResize(rows + 3, Eigen::NoChange);
            for (std::size_t i = 0; i < n; ++i) {
                const glm::vec3 more = glm::max(total[i] - d.radiance[i], glm::vec3(0.0f));
                for (int c = 0; c < 3; ++c) {
                    const Eigen::Index row = rows + c;
                    if (enc.multiple_marched()) { // a log ratio to the isotropic march, as the terms'
                        const double ms = double(more[c]), a = double(d.base(row, Eigen::Index(i)));
                        const bool lit = ms > 0.0 && a > 0.0;
                        const double x = lit ? std::clamp(std::log(ms / a) / double(kResidualRange), -1.0, 1.0)
                                             : 0.0;
                        d.t(row, Eigen::Index(i)) = float(0.5 + 0.5 * double(kEncodeScale) * x);
                        d.mask(row, Eigen::Index(i)) = lit ? 1.0f : 0.0f;
                    } else {
                        d.t(row, Eigen::Index(i)) =
                            encode_log(double(more[c]), enc.multiple_max[c], double(kMultipleLogRange));
                        d.mask(row, Eigen::Index(i)) = 1.0f;
                    }
                }
            }
            d.radiance = std::move(total);
        }
    } else if (enc.outputs == OutputEncoding::PhaseFactored) {
        std::vector<glm::vec3> split;
        split_targets(model, s, split, d.radiance);
        encode_split_targets(enc, split, model.atmosphere().components.size(),
                             phase_term_components(model.atmosphere()), d.t, d.mask);
    } else {
        d.radiance.resize(n);
        sky_targets(model, s, d.radiance, device);
        encode_targets(enc, d.radiance, d.t, d.mask);
    }
    d.mask_count = double(d.mask.sum());
    return d;
}

namespace {

// Xavier/Glorot uniform initialisation scaled for the activation's slope at 0
// (kSlope/4 instead of the logistic's 1/4); biases 0.
std::vector<float> initial_weights(const Layout& lay, std::uint64_t seed) {
    std::vector<float> w(std::size_t(lay.subnets) * std::size_t(lay.subnet_params), 0.0f);
    SplitMix rng{seed};
    for (int s = 0; s < lay.subnets; ++s)
        for (const LayerLayout& L : lay.layers) {
            const double a = std::sqrt(6.0 / double(L.in + L.out)) / (kSlope / 4.0) * 0.5;
            float* p = w.data() + std::size_t(s) * std::size_t(lay.subnet_params) + L.w_offset;
            for (int i = 0; i < L.in * L.out; ++i)
                p[i] = float((2.0 * rng.uniform() - 1.0) * a);
        }
    return w;
}

thread_local Workspace tls_workspace;

struct ErrorPair {
    double rms = 0.0;
    double mean_relative = 0.0;
};

// RMS of the encoded outputs and mean relative RGB error over a data set.
ErrorPair evaluate_set(const Layout& lay, const NeuralSky& net, const DataSet& d) {
    const MlpHD hd = make_mlp_hd(net);
    struct Part {
        double sq = 0.0, rel = 0.0;
        std::size_t lit = 0;
    };
    const Part p = parallel_reduce_chunks(
        d.size(), 2048, Part{},
        [&](std::size_t lo, std::size_t hi) {
            Part part;
            MatF enc(hd.outputs, Eigen::Index(hi - lo));
            forward_network(lay, net.weights.data(), d.x.middleCols(Eigen::Index(lo), Eigen::Index(hi - lo)), enc,
                            tls_workspace);
            const MatF diff = ((enc - d.t.middleCols(Eigen::Index(lo), Eigen::Index(hi - lo))).array() *
                               d.mask.middleCols(Eigen::Index(lo), Eigen::Index(hi - lo)).array())
                                  .matrix();
            part.sq = double(diff.squaredNorm());
            for (std::size_t i = lo; i < hi; ++i) {
                const glm::vec3 ref = d.radiance[i];
                const float n = std::max({ref.x, ref.y, ref.z});
                if (!(n > 0.0f))
                    continue;
                // Row 1 of the inputs is cos β0 in every input encoding.
                const glm::vec3 got = decode_sky(hd, enc.col(Eigen::Index(i - lo)).data(), d.x(1, Eigen::Index(i)),
                                                 d.base.size() ? d.base.col(Eigen::Index(i)).data() : nullptr);
                const glm::dvec3 e = glm::dvec3(got) - glm::dvec3(ref);
                part.rel += std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z) /
                            std::sqrt(double(ref.x) * ref.x + double(ref.y) * ref.y + double(ref.z) * ref.z);
                ++part.lit;
            }
            return part;
        },
        [](Part a, const Part& b) {
            a.sq += b.sq;
            a.rel += b.rel;
            a.lit += b.lit;
            return a;
        });
    return {std::sqrt(p.sq / std::max(1.0, d.mask_count)), p.lit ? p.rel / double(p.lit) : 0.0};
}

struct GradPart {
    double loss = 0.0;
    std::vector<double> g;
};

// Σ mask (y − t)² and its half-gradient over the columns idx[lo, hi) of d.
GradPart batch_gradient(const Layout& lay, const std::vector<float>& w, const DataSet& d,
                        const std::vector<std::uint32_t>& idx, std::size_t lo, std::size_t hi) {
    constexpr std::size_t kChunk = 256;
    const std::size_t P = w.size();
    return parallel_reduce_chunks(
        hi - lo, kChunk, GradPart{0.0, std::vector<double>(P, 0.0)},
        [&](std::size_t b, std::size_t e) {
            GradPart part{0.0, std::vector<double>(P, 0.0)};
            const Eigen::Index n = Eigen::Index(e - b);
            MatF x(d.x.rows(), n), t(d.t.rows(), n), m(d.t.rows(), n);
            for (Eigen::Index j = 0; j < n; ++j) {
                const Eigen::Index c = Eigen::Index(idx[lo + b + std::size_t(j)]);
                x.col(j) = d.x.col(c);
                t.col(j) = d.t.col(c);
                m.col(j) = d.mask.col(c);
            }
            for (int s = 0; s < lay.subnets; ++s)
                part.loss += subnet_loss_grad(lay, w.data(), s, x, t, m,
                                              part.g.data() + std::size_t(s) * std::size_t(lay.subnet_params),
                                              tls_workspace);
            return part;
        },
        [](GradPart a, const GradPart& b) {
            a.loss += b.loss;
            for (std::size_t i = 0; i < a.g.size(); ++i)
                a.g[i] += b.g[i];
            return a;
        });
}

// Σ mask (y − t)² of sub-network s over the first n samples.
double subnet_loss(const Layout& lay, const std::vector<float>& w, int s, const DataSet& d, std::size_t n) {
    return parallel_reduce_chunks(
        n, 4096, 0.0,
        [&](std::size_t lo, std::size_t hi) {
            const Eigen::Index a = Eigen::Index(lo), k = Eigen::Index(hi - lo);
            return subnet_loss_grad(lay, w.data(), s, d.x.middleCols(a, k), d.t.middleCols(a, k),
                                    d.mask.middleCols(a, k), nullptr, tls_workspace);
        },
        [](double a, double b) { return a + b; });
}

struct NormalPart {
    Eigen::MatrixXd jtj;
    Eigen::VectorXd jtr;
    double loss = 0.0;
};

NormalPart normal_equations(const Layout& lay, const std::vector<float>& w, int s, const DataSet& d, std::size_t n) {
    const int P = lay.subnet_params;
    // At most ~16 partial matrices, whatever the thread count.
    const std::size_t chunk = std::max<std::size_t>(8192, (n + 15) / 16);
    NormalPart init{Eigen::MatrixXd::Zero(P, P), Eigen::VectorXd::Zero(P), 0.0};
    return parallel_reduce_chunks(
        n, chunk, init,
        [&](std::size_t lo, std::size_t hi) {
            Eigen::MatrixXf jtj = Eigen::MatrixXf::Zero(P, P);
            Eigen::VectorXf jtr = Eigen::VectorXf::Zero(P);
            NormalPart part{Eigen::MatrixXd::Zero(P, P), Eigen::VectorXd::Zero(P), 0.0};
            constexpr std::size_t kBlock = 512, kFlush = 8192;
            for (std::size_t b = lo; b < hi; b += kBlock) {
                const Eigen::Index a = Eigen::Index(b), k = Eigen::Index(std::min(hi, b + kBlock) - b);
                part.loss += subnet_normal_equations(lay, w.data(), s, d.x.middleCols(a, k), d.t.middleCols(a, k),
                                                     d.mask.middleCols(a, k), jtj, jtr, tls_workspace);
                if ((b - lo + kBlock) % kFlush == 0 || b + kBlock >= hi) { // flush float sums into double
                    part.jtj += jtj.cast<double>();
                    part.jtr += jtr.cast<double>();
                    jtj.setZero();
                    jtr.setZero();
                }
            }
            return part;
        },
        [](NormalPart a, const NormalPart& b) {
            a.jtj += b.jtj;
            a.jtr += b.jtr;
            a.loss += b.loss;
            return a;
        });
}

} // namespace

std::vector<double> neural::fit_multiple_psi(const SkyModel& model, double mu_s_min, Device device) {
    // The sky's mean radiance over the sphere (a Fibonacci sphere of 512
    // directions) at 25 altitudes × 121 sun elevations, uniform from the
    // ground to the top and from asin(mu_s_min) to 90°.
    const Atmosphere& atm = model.atmosphere();
    constexpr int kAltitudes = 25, kElevations = 121, kDirections = 512;
    const double pi = 3.14159265358979323846, golden = pi * (3.0 - std::sqrt(5.0));
    const double top = atm.top_radius_km - atm.planet_radius_km, e0 = std::asin(mu_s_min);
    std::vector<SkySample> s;
    s.reserve(std::size_t(kAltitudes * kElevations * kDirections));
    std::vector<glm::dvec2> node; // (x, y) of each node, as psi_log maps them
    for (int ih = 0; ih < kAltitudes; ++ih) {
        const double h = top * ih / (kAltitudes - 1);
        const float rho = float(std::max(atm.density_from_altitude(h), 1e-30));
        for (int ie = 0; ie < kElevations; ++ie) {
            const double mu_s = std::sin(e0 + (pi / 2 - e0) * ie / (kElevations - 1));
            const double ss = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
            node.push_back({2.0 * h / top - 1.0, (2.0 * mu_s - 1.0 - mu_s_min) / (1.0 - mu_s_min)});
            for (int i = 0; i < kDirections; ++i) {
                const double z = 1.0 - 2.0 * (i + 0.5) / kDirections, x = std::sqrt(std::max(0.0, 1.0 - z * z));
                const double nu = z * mu_s + x * ss * std::cos(golden * i);
                s.push_back({float(z), float(std::clamp(nu, -1.0, 1.0)), float(mu_s), rho});
            }
        }
    }
    std::vector<glm::vec3> radiance(s.size());
    sky_targets(model, s, radiance, device);
    const Eigen::Index rows = Eigen::Index(node.size());
    Eigen::MatrixXd A(rows, kPsiCoefficients), b(rows, 3);
    for (Eigen::Index n = 0; n < rows; ++n) {
        glm::dvec3 mean(0.0);
        for (int i = 0; i < kDirections; ++i)
            mean += glm::dvec3(radiance[std::size_t(n) * kDirections + std::size_t(i)]);
        mean /= double(kDirections);
        for (int c = 0; c < 3; ++c)
            b(n, c) = std::log(std::max(mean[c], 1e-30));
        double xi = 1.0;
        for (int i = 0; i <= kPsiAltitudeDegree; ++i, xi *= node[std::size_t(n)].x) {
            double yj = 1.0;
            for (int j = 0; j <= kPsiSunDegree; ++j, yj *= node[std::size_t(n)].y)
                A(n, i * (kPsiSunDegree + 1) + j) = xi * yj;
        }
    }
    const Eigen::MatrixXd a = A.colPivHouseholderQr().solve(b);
    std::vector<double> out;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < kPsiCoefficients; ++i)
            out.push_back(a(i, c));
    return out;
}

double neural::effective_flight_share(const NeuralTrainOptions& o, const Atmosphere& atmosphere) {
    if (o.flight_share >= 0.0)
        return o.flight_share;
    return atmosphere.scattering == Scattering::Single ? 0.0 : kMultipleFlightShare;
}

NeuralSchedule training_schedule(const NeuralTopology& topology) {
    int widest = 0;
    for (int w : topology.hidden)
        widest = std::max(widest, w);
    if (widest <= 16)
        return {60, 0.02, 20};
    if (widest <= 32)
        return {60, 0.02, 3};
    if (widest <= 64)
        return {150, 0.01, 0};
    return {30, 0.005, 0};
}

OutputEncoding default_output_encoding(const Atmosphere& atmosphere) {
    NeuralEncoding e;
    e.outputs = OutputEncoding::Residual;
    e.multiple = atmosphere.scattering != Scattering::Single;
    for (int k : phase_term_components(atmosphere))
        e.terms.push_back({atmosphere.components[std::size_t(k)].name});
    try {
        check_residual_atmosphere(e, atmosphere, "atmosphere");
    } catch (const Error&) {
        return e.multiple ? OutputEncoding::Radiance : OutputEncoding::PhaseFactored;
    }
    return OutputEncoding::Residual;
}

std::uint64_t neural::stream_seed(std::uint64_t seed, std::uint64_t stream) {
    SplitMix64 r{seed ^ (stream * 0xA0761D6478BD642Full)};
    r.next();
    return r.next();
}

NeuralEncoding neural::make_training_encoding(const SkyModel& model, const NeuralTrainOptions& o) {
    if ((o.brightness == BrightnessEncoding::Log || has_phase_terms(o.outputs)) &&
        !(o.log_range > 0.0 && o.log_range < 200.0))
        throw Error("the log range must be in (0, 200) nats", "log_range");
    const std::vector<int> term_components = phase_term_components(model.atmosphere());
    if (has_phase_terms(o.outputs)) {
        if (o.outputs == OutputEncoding::PhaseFactored && model.atmosphere().scattering != Scattering::Single)
            throw Error("phase-factored outputs are exact for single scattering only; use outputs residual or "
                        "radiance for an atmosphere with multiple scattering",
                        "outputs");
        if (o.brightness != BrightnessEncoding::Log)
            throw Error("phase-factored outputs are log-encoded; the linear brightness is for radiance outputs",
                        "brightness");
        if (term_components.empty() || term_components.size() > std::size_t(kMaxTerms))
            throw Error("phase-factored outputs need 1 to 4 scattering components in the atmosphere", "outputs");
    }

    NeuralEncoding encoding;
    encoding.inputs = o.inputs;
    encoding.outputs = o.outputs;
    encoding.brightness = o.brightness;
    encoding.log_range = o.log_range;
    {   // max{N} (and max S_k per channel) over random samples (the seed's 100,000)
        const std::vector<SkySample> s = draw_sky_samples(o.max_n_samples, stream_seed(o.seed, 2));
        std::vector<glm::vec3> r, split;
        if (has_phase_terms(o.outputs)) {
            split_targets(model, s, split, r);
            const std::size_t nc = model.atmosphere().components.size();
            for (int k : term_components) {
                const AtmosphereComponent& c = model.atmosphere().components[std::size_t(k)];
                PhaseTerm t{c.name, c.phase, c.phase_g, glm::dvec3(0.0)};
                for (std::size_t i = 0; i < s.size(); ++i)
                    t.max_s = glm::max(t.max_s, glm::dvec3(split[i * nc + std::size_t(k)]));
                for (int ch = 0; ch < 3; ++ch)
                    if (!(t.max_s[ch] > 0.0))
                        t.max_s[ch] = 1e-30; // a channel this component never scatters: decoded as (almost) 0
                encoding.terms.push_back(t);
            }
            if (o.outputs == OutputEncoding::Residual && model.atmosphere().scattering != Scattering::Single) {
                // The multiple-scattering term: the total less the single scattering.
                std::vector<glm::vec3> total(s.size());
                sky_targets(model, s, total, o.device);
                encoding.multiple = true;
                encoding.multiple_max = glm::dvec3(1e-30);
                for (std::size_t i = 0; i < s.size(); ++i)
                    encoding.multiple_max = glm::max(encoding.multiple_max, glm::dvec3(total[i] - r[i]));
                if (o.multiple_march)
                    encoding.multiple_psi = fit_multiple_psi(model, encoding.multiple_psi_mu_min, o.device);
                r = std::move(total);
            }
        } else {
            r.resize(s.size());
            sky_targets(model, s, r, o.device);
        }
        double mx = 0.0;
        for (const glm::vec3& c : r)
            mx = std::max(mx, double(std::max({c.x, c.y, c.z})));
        if (!(mx > 0.0))
            throw Error("the sky is black on every sample; check the atmosphere's scattering coefficients",
                        "atmosphere");
        encoding.max_n = mx;
    }
    if (o.outputs == OutputEncoding::Residual)
        check_residual_atmosphere(encoding, model.atmosphere(), "outputs");
    if (!o.family_component.empty()) {
        encoding.family_component = o.family_component;
        encoding.aerosol_min = o.aerosol_min;
        encoding.aerosol_max = o.aerosol_max;
        check_family(encoding, model.atmosphere(), "family_component");
    }
    return encoding;
}

NeuralSky train_neural_sky(const SkyModel& model, const NeuralTrainOptions& o, std::vector<LearningCurvePoint>* curve) {
    o.topology.validate("topology");
    if (o.samples < 16 || o.samples > (std::size_t(1) << 31))
        throw Error("the number of training samples must be 16 to 2^31", "samples");
    if (o.heldout_samples < 1 || o.max_n_samples < 1)
        throw Error("held-out and max{N} sample counts must be at least 1", "heldout_samples");
    if (o.adam_epochs < 0 || o.lm_iterations < 0 || o.adam_epochs + o.lm_iterations > 100000)
        throw Error("epochs and LM iterations must be 0 to 100000", "adam_epochs/lm_iterations");
    if (o.batch < 1 || o.batch > o.samples)
        throw Error("the mini-batch must hold 1 to `samples` samples", "batch");
    if (!(o.hard_share >= 0.0 && o.hard_share <= 1.0))
        throw Error("the share of hard samples must be in [0, 1]", "hard_share");
    if (!(o.flight_share <= 1.0) || (o.flight_share < 0.0 && o.flight_share != -1.0))
        throw Error("the share of a flight's samples must be in [0, 1], or -1 for automatic", "flight_share");
    if (!(o.learning_rate > 0.0 && o.learning_rate_final > 0.0 && o.learning_rate < 10.0))
        throw Error("learning rates must be positive (and below 10)", "learning_rate");
    if ((o.brightness == BrightnessEncoding::Log || has_phase_terms(o.outputs)) &&
        !(o.log_range > 0.0 && o.log_range < 200.0))
        throw Error("the log range must be in (0, 200) nats", "log_range");
    const auto t0 = std::chrono::steady_clock::now();
    NeuralSky net;
    net.topology = o.topology;
    net.atmosphere = model.atmosphere();
    net.sky_options = model.options();
    net.encoding = make_training_encoding(model, o);
    net.topology.outputs = net.encoding.output_count();
    net.topology.inputs = net.encoding.input_count();
    const DataSet train =
        make_training_data(model, net.encoding, o.samples, stream_seed(o.seed, 0), o.device, o.hard_share,
                           effective_flight_share(o, model.atmosphere()));
    const DataSet held = make_training_data(model, net.encoding, o.heldout_samples, stream_seed(o.seed, 1), o.device);
    return train_network(std::move(net), train, held, o, curve, t0);
}

NeuralSky neural::train_network(NeuralSky net, const TrainingData& train, const TrainingData& held,
                                const NeuralTrainOptions& o, std::vector<LearningCurvePoint>* curve,
                                std::chrono::steady_clock::time_point t0) {
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    const Layout lay = make_layout(net.topology);
    net.weights = initial_weights(lay, stream_seed(o.seed, 3));
    const std::size_t P = net.weights.size();

    std::optional<Progress> progress;
    if (o.progress)
        progress.emplace("train", std::uint64_t(o.adam_epochs + o.lm_iterations));
    auto record = [&](int epoch, const char* phase, double train_rms) {
        const ErrorPair h = evaluate_set(lay, net, held);
        net.training.train_rms = train_rms;
        net.training.heldout_rms = h.rms;
        net.training.heldout_mean_relative = h.mean_relative;
        if (curve)
            curve->push_back({epoch, phase, train_rms, h.rms, h.mean_relative, elapsed()});
        if (progress) {
            progress->set_status(fmt::format("{} loss {:.4g}, held-out RMS {:.4g}", phase, train_rms, h.rms));
            progress->advance();
        }
    };

    // --- Adam --------------------------------------------------------------------
    std::vector<double> m(P, 0.0), v(P, 0.0);
    const double beta1 = 0.9, beta2 = 0.999, eps = 1e-8;
    double beta1_t = 1.0, beta2_t = 1.0;
    std::vector<std::uint32_t> perm(train.size());
    std::iota(perm.begin(), perm.end(), 0u);
    SplitMix shuffle_rng{stream_seed(o.seed, 4)};
    for (int epoch = 0; epoch < o.adam_epochs; ++epoch) {
        const double f = o.adam_epochs > 1 ? double(epoch) / double(o.adam_epochs - 1) : 0.0;
        const double lr = o.learning_rate * std::pow(o.learning_rate_final / o.learning_rate, f);
        for (std::size_t i = perm.size() - 1; i > 0; --i) // Fisher–Yates
            std::swap(perm[i], perm[std::size_t(shuffle_rng.next() % (i + 1))]);
        double epoch_loss = 0.0;
        for (std::size_t lo = 0; lo < train.size(); lo += o.batch) {
            const std::size_t hi = std::min(train.size(), lo + o.batch);
            const GradPart g = batch_gradient(lay, net.weights, train, perm, lo, hi);
            epoch_loss += g.loss;
            beta1_t *= beta1;
            beta2_t *= beta2;
            const double scale = 1.0 / double(hi - lo);
            const double step = lr * std::sqrt(1.0 - beta2_t) / (1.0 - beta1_t);
            for (std::size_t i = 0; i < P; ++i) {
                const double gi = g.g[i] * scale;
                m[i] = beta1 * m[i] + (1.0 - beta1) * gi;
                v[i] = beta2 * v[i] + (1.0 - beta2) * gi * gi;
                net.weights[i] -= float(step * m[i] / (std::sqrt(v[i]) + eps));
            }
        }
        record(epoch + 1, "adam", std::sqrt(epoch_loss / std::max(1.0, train.mask_count)));
    }

    // --- Levenberg–Marquardt, one sub-network at a time --------------------------------
    const double Pd = double(lay.subnet_params);
    // Automatic: the normal equations cost rows × P² with one row per sample
    // and output of the sub-network; about 1e10 of that per iteration, at
    // most 200,000 and at least 10 P samples.
    const double rows_per_sample = double(lay.outputs);
    const std::size_t n_lm =
        o.lm_samples ? std::min(o.lm_samples, train.size())
                     : std::min(train.size(), std::max(std::size_t(10.0 * Pd),
                                                       std::size_t(std::min(2e5, 1e10 / (Pd * Pd * rows_per_sample)))));
    std::vector<double> lambda(std::size_t(lay.subnets), 1e-3);
    std::vector<bool> done(std::size_t(lay.subnets), false);
    int lm_run = 0;
    for (int it = 0; it < o.lm_iterations; ++it) {
        bool any = false;
        for (int s = 0; s < lay.subnets; ++s) {
            if (done[std::size_t(s)])
                continue;
            any = true;
            const NormalPart ne = normal_equations(lay, net.weights, s, train, n_lm);
            Eigen::MatrixXd A = ne.jtj.selfadjointView<Eigen::Lower>();
            const Eigen::VectorXd diag = A.diagonal();
            const double floor = 1e-9 * std::max(1e-30, diag.mean());
            float* ws = net.weights.data() + std::size_t(s) * std::size_t(lay.subnet_params);
            const std::vector<float> saved(ws, ws + lay.subnet_params);
            bool accepted = false;
            for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
                Eigen::MatrixXd Ad = A;
                Ad.diagonal() += lambda[std::size_t(s)] * diag + Eigen::VectorXd::Constant(A.rows(), floor);
                const Eigen::VectorXd step = Ad.ldlt().solve(-ne.jtr);
                for (int i = 0; i < lay.subnet_params; ++i)
                    ws[i] = float(double(saved[std::size_t(i)]) + step(i));
                const double loss = step.allFinite() ? subnet_loss(lay, net.weights, s, train, n_lm) : INFINITY;
                if (loss < ne.loss) {
                    accepted = true;
                    lambda[std::size_t(s)] = std::max(1e-12, lambda[std::size_t(s)] / 3.0);
                    if (ne.loss - loss < 1e-7 * ne.loss)
                        done[std::size_t(s)] = true; // converged
                } else {
                    std::copy(saved.begin(), saved.end(), ws);
                    lambda[std::size_t(s)] *= 4.0;
                }
            }
            if (!accepted)
                done[std::size_t(s)] = true;
        }
        if (!any)
            break;
        ++lm_run;
        double train_loss = 0.0;
        for (int s = 0; s < lay.subnets; ++s)
            train_loss += subnet_loss(lay, net.weights, s, train, train.size());
        record(o.adam_epochs + lm_run, "lm", std::sqrt(train_loss / std::max(1.0, train.mask_count)));
    }
    if (progress)
        progress->finish();
    if (o.adam_epochs + lm_run == 0) { // nothing trained: still fill in the summary
        const ErrorPair h = evaluate_set(lay, net, held);
        net.training.train_rms = evaluate_set(lay, net, train).rms;
        net.training.heldout_rms = h.rms;
        net.training.heldout_mean_relative = h.mean_relative;
    }
    net.training.samples = o.samples;
    net.training.heldout_samples = o.heldout_samples;
    net.training.seed = o.seed;
    net.training.adam_epochs = o.adam_epochs;
    net.training.lm_iterations = lm_run;
    net.training.threads = thread_count();
    net.training.seconds = elapsed();
    return net;
}

} // namespace skybake
