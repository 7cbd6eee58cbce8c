// Internal batch maths of the neural sky (Eigen, CPU): layout, batched forward
// and backward passes, Jacobians. Shared by inference, training and tests.
#pragma once

#include <vector>

#include <Eigen/Core>

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
MlpHD make_mlp_hd(const NeuralSky& net);

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

// Inputs (4 × n) from samples.
MatF samples_to_matrix(std::span<const SkySample> samples);

} // namespace skybake::neural
