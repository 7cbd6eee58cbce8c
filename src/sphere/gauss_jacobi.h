// Gauss–Jacobi quadrature on [0, 1] for the weight t^a (internal).
#pragma once

#include <vector>

namespace skybake::sphere {

struct GaussRule1D {
    std::vector<double> nodes;   // in (0, 1), ascending
    std::vector<double> weights; // sum to 1: Σ w_i g(t_i) = ∫_0^1 g(t) t^a dt / ∫_0^1 t^a dt
};

// n-point rule, exact for polynomials g of degree ≤ 2n − 1. a ≥ 0, n ≥ 1.
GaussRule1D gauss_jacobi_unit(int n, double exponent_a);

} // namespace skybake::sphere
