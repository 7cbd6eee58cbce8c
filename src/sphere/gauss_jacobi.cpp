// Golub G. H., Welsch J. H. Calculation of Gauss quadrature rules. Math. Comp.
// 23, 1969, 221-230: the nodes are the eigenvalues of the Jacobi matrix of the
// three-term recurrence and the weights the squared first components of its
// eigenvectors. Recurrence of the Jacobi polynomials P_n^(α,β) for the weight
// (1 − x)^α (1 + x)^β on [−1, 1] (Abramowitz & Stegun 22.7.1); here α = 0,
// β = a, and x = 2t − 1 maps it to t^a on [0, 1].
#include "sphere/gauss_jacobi.h"

#include <cassert>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace skybake::sphere {

GaussRule1D gauss_jacobi_unit(int n, double a) {
    assert(n >= 1 && a >= 0.0);
    const double alpha = 0.0, beta = a, ab = alpha + beta;
    Eigen::VectorXd diag(n), sub(n > 1 ? n - 1 : 0);
    for (int k = 0; k < n; ++k) {
        const double s = 2.0 * k + ab;
        diag[k] = (k == 0 && ab == 0.0) ? 0.0
                  : k == 0              ? (beta - alpha) / (ab + 2.0)
                                        : (beta * beta - alpha * alpha) / (s * (s + 2.0));
    }
    for (int k = 1; k < n; ++k) {
        const double s = 2.0 * k + ab;
        sub[k - 1] = std::sqrt(4.0 * k * (k + alpha) * (k + beta) * (k + ab) / (s * s * (s + 1.0) * (s - 1.0)));
    }
    GaussRule1D rule;
    rule.nodes.resize(std::size_t(n));
    rule.weights.resize(std::size_t(n));
    if (n == 1) {
        rule.nodes[0] = 0.5 * (1.0 + diag[0]);
        rule.weights[0] = 1.0;
        return rule;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver;
    solver.computeFromTridiagonal(diag, sub, Eigen::ComputeEigenvectors);
    const Eigen::VectorXd& x = solver.eigenvalues(); // ascending
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
        const double v0 = solver.eigenvectors()(0, i);
        rule.nodes[std::size_t(i)] = 0.5 * (1.0 + x[i]);
        rule.weights[std::size_t(i)] = v0 * v0;
        total += v0 * v0;
    }
    for (double& w : rule.weights)
        w /= total;
    return rule;
}

} // namespace skybake::sphere
