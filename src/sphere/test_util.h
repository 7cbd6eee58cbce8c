// Helpers shared by the sphere unit tests: closed-form monomial integrals.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "skybake/sphere.h"

namespace skybake::sphere_test {

// ∫ x^i y^j z^k dμ over the unit sphere, normalised measure dμ = dω/4π:
//   Γ((i+1)/2) Γ((j+1)/2) Γ((k+1)/2) / (2π Γ((i+j+k+3)/2)) for even i, j, k, else 0.
// (From ∫_S² x^i y^j z^k dω = 2 Γ Γ Γ / Γ((i+j+k+3)/2), Folland, "How to integrate a
// polynomial over a sphere", Amer. Math. Monthly 108, 2001. REFERENCE.md prints
// 2π^(3/2) in the denominator; that gives 1/√π for i = j = k = 0, not 1.)
inline double sphere_monomial(int i, int j, int k) {
    if (i % 2 || j % 2 || k % 2)
        return 0.0;
    const double pi = 3.141592653589793;
    return std::exp(std::lgamma((i + 1) / 2.0) + std::lgamma((j + 1) / 2.0) + std::lgamma((k + 1) / 2.0) -
                    std::lgamma((i + j + k + 3) / 2.0)) /
           (2.0 * pi);
}

// ∫ x^i y^j z^k ρ_a dμ with the normalised Phong lobe ρ_a = 2(a+1) max(z,0)^a:
// over the upper hemisphere ∫ x^i y^j z^c dω = Γ Γ Γ((c+1)/2) / Γ((i+j+c+3)/2) (half
// the full-sphere value of |z|^c), c = k + a, for even i, j; else 0.
inline double phong_monomial(int i, int j, int k, double a) {
    if (i % 2 || j % 2)
        return 0.0;
    const double pi = 3.141592653589793, c = k + a;
    return 2.0 * (a + 1.0) / (4.0 * pi) *
           std::exp(std::lgamma((i + 1) / 2.0) + std::lgamma((j + 1) / 2.0) + std::lgamma((c + 1) / 2.0) -
                    std::lgamma((i + j + c + 3) / 2.0));
}

// Max |Σ w x^i y^j z^k − ∫ x^i y^j z^k dμ| over the monomials of degree ≤ p: every
// even one, and a sample of the odd ones (which vanish by symmetry for Lebedev rules
// and designs alike).
inline double monomial_error(const SphereRule& r, int p) {
    const std::size_t np = r.size(), stride = std::size_t(p + 1);
    std::vector<double> px(np * stride), py(np * stride), pz(np * stride);
    for (std::size_t q = 0; q < np; ++q) {
        px[q * stride] = py[q * stride] = pz[q * stride] = 1.0;
        for (int e = 1; e <= p; ++e) {
            px[q * stride + e] = px[q * stride + e - 1] * r.points[q].x;
            py[q * stride + e] = py[q * stride + e - 1] * r.points[q].y;
            pz[q * stride + e] = pz[q * stride + e - 1] * r.points[q].z;
        }
    }
    double worst = 0.0;
    for (int i = 0; i <= p; ++i)
        for (int j = 0; i + j <= p; ++j)
            for (int k = 0; i + j + k <= p; ++k) {
                const bool even = i % 2 == 0 && j % 2 == 0 && k % 2 == 0;
                if (!even && (i + 2 * j + 3 * k) % 17 != 0)
                    continue;
                double s = 0.0;
                for (std::size_t q = 0; q < np; ++q)
                    s += r.weights[q] * px[q * stride + i] * py[q * stride + j] * pz[q * stride + k];
                worst = std::max(worst, std::abs(s - sphere_monomial(i, j, k)));
            }
    return worst;
}

} // namespace skybake::sphere_test
