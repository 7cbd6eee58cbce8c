// Internal batch maths of the neural sky (Eigen, CPU): layout, batched forward
// and backward passes, Jacobians. Shared by inference, training and tests.
#pragma once

#include <chrono>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "neural/device.h"
#include "neural/mlp_hd.h"
#include "skybake/neural.h"

namespace skybake::neural {

using MatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>; // column-major: one sample per column
using VecD = Eigen::VectorXd;

struct LayerLayout {
    int in = 0, out = 0;
    int w_offset = 0; // W_l, row-major [out][in], within the sub-network
    int b_offset = 0; // b_l [out]
};

struct Layout {
    std::vector<LayerLayout> layers;
    int subnets = 4;
    int outputs = 1; // per sub-network
    int subnet_params = 0;
};

Layout make_layout(const NeuralTopology& topology);
// The encoding part of MlpHD (inputs, decoding constants, phase terms).
void set_encoding_hd(const NeuralEncoding& encoding, const Atmosphere& atmosphere, MlpHD& m);
// Throws skybake::Error (naming `where`) unless the atmosphere suits residual
// outputs: single scattering, at most kMaxTerms exponential components, and
// every term's component among them.
void check_residual_atmosphere(const NeuralEncoding& encoding, const Atmosphere& atmosphere,
                               const std::string& where);
// Throws skybake::Error (naming `where`: encoding.family) unless the
// encoding's aerosol family is one the network can carry: residual outputs of
// single scattering, a scattering component of the atmosphere, a valid range.
void check_family(const NeuralEncoding& encoding, const Atmosphere& atmosphere, const std::string& where);
// Indices of the atmosphere's components that scatter (a phase function and
// some scattering): the phase-factored terms, in order.
std::vector<int> phase_term_components(const Atmosphere& atmosphere);
// 0.05 + 0.9 max(0, 1 + ln(value/max)/log_range), at most 0.95; 0 for value ≤ 0.
float encode_log(double value, double max, double log_range);

// Per-thread scratch for the batched passes.
struct Workspace {
    std::vector<MatF> a;     // activations of layers 1..L (a[l] is layer l+1's output)
    std::vector<MatF> delta; // back-propagated errors per layer
};

// a[l] = f(W_l a[l−1] + b_l) over the columns of x (4 × B).
void forward_subnet(const Layout& layout, const float* w, const Eigen::Ref<const MatF>& x, Workspace& ws);

// Encoded outputs (4 × B) of the whole network for inputs x (4 × B).
void forward_network(const Layout& layout, const float* weights, const Eigen::Ref<const MatF>& x,
                     Eigen::Ref<MatF> out, Workspace& ws);

// Masked squared error Σ mask (y − t)² of sub-network s over a batch; when
// grad is not null, adds ∂/∂w of ½ Σ mask (y − t)² to grad[0 .. subnet_params).
// t and mask are 4 × B (rows of the sub-network's outputs are used).
double subnet_loss_grad(const Layout& layout, const float* w, int s, const Eigen::Ref<const MatF>& x,
                        const Eigen::Ref<const MatF>& t, const Eigen::Ref<const MatF>& mask, double* grad,
                        Workspace& ws);

// Gauss–Newton pieces of sub-network s over a batch: adds Jᵀ J (lower
// triangle) to jtj and Jᵀ r to jtr, with r = mask (y − t) and J = ∂(mask y)/∂w.
// Returns Σ r².
double subnet_normal_equations(const Layout& layout, const float* w, int s, const Eigen::Ref<const MatF>& x,
                               const Eigen::Ref<const MatF>& t, const Eigen::Ref<const MatF>& mask,
                               Eigen::MatrixXf& jtj, Eigen::VectorXf& jtr, Workspace& ws);

// Training targets: encoded radiance (4 × n) and mask (4 × n; the R, G, B rows are 0 at night).
void encode_targets(const NeuralEncoding& encoding, std::span<const glm::vec3> radiance, MatF& targets, MatF& mask);

// Phase-factored targets (3 per term × n) from the split sums (n × components,
// sky::evaluate_sky_split); every output is trained (mask 1).
void encode_split_targets(const NeuralEncoding& encoding, std::span<const glm::vec3> split, std::size_t components,
                          const std::vector<int>& term_components, MatF& targets, MatF& mask);
// Residual targets: 0.5 + 0.45 clamp(ln(S/A)/kResidualRange, −1, 1) per term
// and channel, A from `base` (analytic_matrix); masked out where S or A is 0
// (nothing to correct: the output is A·ratio = 0 there, or S is 0).
void encode_residual_targets(std::span<const glm::vec3> split, std::size_t components,
                             const std::vector<int>& term_components, const MatF& base, MatF& targets, MatF& mask);

// The random stream `stream` of a training seed: 0 training samples, 1
// held-out, 2 max{N}, 3 initial weights, 4 shuffles.
std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t stream);

// Training or held-out data: inputs, encoded targets, masks, and the reference radiance.
struct TrainingData {
    MatF x, t, mask;
    MatF base; // residual outputs: analytic_terms per sample (3 per term), else empty
    std::vector<glm::vec3> radiance;
    std::vector<float> aerosol; // an aerosol family: each sample's amount, else empty
    double mask_count = 0.0;
    std::size_t size() const { return radiance.size(); }
};
// fit_sky_lookup_table minimises, per output, with D the mean over nodes of
// Σ_samples mask w_j² (the normal matrix's mean diagonal):
//   Σ_samples mask (Σ_j w_j v_j − t)²  +  kTableRidge D Σ_j v_j²
//     +  kTableSmoothing D Σ_(neighbours j, k along one input) (v_j − v_k)²
// The smoothing keeps nodes that few samples touch near their neighbours:
// without it, the least squares put them anywhere (codes of ±170 at 8⁴ nodes
// for codes that lie in [0, 1]) and their cells overflowed the decoding.
constexpr double kTableRidge = 1e-6, kTableSmoothing = 1e-3;

// The encoding train_neural_sky trains with: options' encodings, max{N}
// (and max S per phase term) over options.max_n_samples samples. Throws
// skybake::Error naming the option for combinations that cannot work.
NeuralEncoding make_training_encoding(const SkyModel& model, const NeuralTrainOptions& options);
// An aerosol family's amounts for n samples of `seed`: log-uniform over the range.
std::vector<float> draw_aerosol(const NeuralEncoding& encoding, std::size_t n, std::uint64_t seed);
// The atmosphere's index of the family's component (−1: none).
int family_component_index(const NeuralEncoding& encoding, const Atmosphere& atmosphere);
// n samples (seed) of model's table path with their encoded targets.
TrainingData make_training_data(const SkyModel& model, const NeuralEncoding& encoding, std::size_t n,
                                std::uint64_t seed, Device device, double hard_share = 0.0,
                                double flight_share = 0.0);
// n samples where the sky is hard for a network (NeuralTrainOptions::hard_share),
// a third each: views within sin 2° (in cosine) of the geometric horizon, within 15° of the sun,
// and suns from −15° to 5°; densities uniform in (0, 1] as draw_sky_samples.
std::vector<SkySample> draw_hard_samples(std::size_t n, std::uint64_t seed, const Atmosphere& atmosphere);

// train_neural_sky after its data: Adam, then Levenberg–Marquardt, on `net`
// (its topology, encoding and atmosphere set; its weights are replaced).
// t0: when training started, for the curve's seconds.
NeuralSky train_network(NeuralSky net, const TrainingData& train, const TrainingData& held,
                        const NeuralTrainOptions& options, std::vector<LearningCurvePoint>* curve,
                        std::chrono::steady_clock::time_point t0);

// The held-out errors and view PSNRs of measure_neural_sky_error for any
// approximation of `model`'s table path: a batch evaluator and a renderer.
// With an aerosol family (`family` not null), each sample gets an amount
// (draw_aerosol), the reference is the table path with the family's
// component scaled by it, and the views are rendered at the range's ends and
// its geometric middle; the evaluator and renderer receive the amounts (empty
// and 1 without a family).
using BatchSky = std::function<void(std::span<const SkySample>, std::span<const float> aerosol, std::span<glm::vec3>)>;
// The renderer gets the view, the aerosol amount and the reference model at
// that amount (its tables shade the ground and the sun disc).
using RenderSky = std::function<Image(const SkyRenderSettings&, double aerosol, const SkyModel& tables)>;
NeuralErrorReport measure_approximation_error(const SkyModel& model, double max_n, const NeuralErrorOptions& options,
                                              const BatchSky& evaluate, const RenderSky& render,
                                              const NeuralEncoding* family = nullptr);
// The table path of `model` with component `component` scaled by each
// sample's amount (an aerosol family's reference): Σ_k P_k S_k of the split sums.
void scaled_sky_targets(const SkyModel& model, std::span<const SkySample> samples, std::span<const float> aerosol,
                        int component, std::vector<glm::vec3>& split, std::vector<glm::vec3>& radiance);
// The atmosphere with the family's component scaled by `aerosol`.
Atmosphere scaled_atmosphere(const NeuralEncoding& family, const Atmosphere& atmosphere, double aerosol);

// Network inputs (m.width[0] × n) from samples, through the input encoding of
// m; `aerosol`, when not empty, holds each sample's aerosol amount (a family).
MatF samples_to_matrix(const MlpHD& m, std::span<const SkySample> samples, std::span<const float> aerosol = {});
// NeuralTrainOptions::flight_share, with its automatic value resolved.
constexpr double kMultipleFlightShare = 0.4;
double effective_flight_share(const NeuralTrainOptions& options, const Atmosphere& atmosphere);

// ln ψ's coefficients (NeuralEncoding::multiple_psi) for the model's sky:
// the polynomial of psi_log fitted by least squares to the log of the sky's
// mean radiance over the sphere, at altitudes from the ground to the top and
// sun cosines from mu_s_min to 1.
std::vector<double> fit_multiple_psi(const SkyModel& model, double mu_s_min, Device device);
// analytic_base of the samples: 3 per term, and 3 more for a marched
// multiple-scattering term, × n.
MatF analytic_matrix(const MlpHD& m, std::span<const SkySample> samples, std::span<const float> aerosol = {});
// evaluate_neural_sky with each sample's own aerosol amount (empty: net.aerosol).
void evaluate_neural_sky_at(const NeuralSky& net, std::span<const SkySample> samples, std::span<const float> aerosol,
                            std::span<glm::vec3> out);

} // namespace skybake::neural
