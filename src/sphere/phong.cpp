// Phong-lobe rules for DPRT (seed 002, "PRT and DPRT"): a weighted cubature for
// the weight ρ_a = 2(a + 1) max(cos θ, 0)^a, built as a product rule: Gauss–Jacobi
// in t = cos θ for t^a (gauss_jacobi.cpp) times the trapezoidal rule in φ, which
// is exact for trigonometric polynomials of degree < 2n (Stroud 1971, ch. 8).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/sphere.h"
#include "sphere/gauss_jacobi.h"

namespace skybake {

SphereRule phong_rule(double a, int n) {
    if (!(a >= 0.0) || !std::isfinite(a))
        throw Error(fmt::format("the Phong exponent must be a finite number ≥ 0, got {}", a), "phong:a=A");
    if (n < 1 || n > 512)
        throw Error(fmt::format("the Phong rule needs 1 to 512 nodes in cos θ, got {}", n), "phong:n=N");
    const sphere::GaussRule1D gj = sphere::gauss_jacobi_unit(n, a);
    SphereRule rule;
    rule.kind = RuleKind::Phong;
    rule.precision = 2 * n - 1;
    rule.spec = fmt::format("phong:a={},n={}", a, n);
    const int azimuths = 2 * n;
    rule.points.reserve(std::size_t(n) * std::size_t(azimuths));
    rule.weights.reserve(rule.points.capacity());
    const double pi = 3.141592653589793;
    for (int i = 0; i < n; ++i) {
        const double t = gj.nodes[std::size_t(i)];
        const double r = std::sqrt(std::max(0.0, 1.0 - t * t));
        for (int j = 0; j < azimuths; ++j) {
            const double phi = pi * j / n;
            rule.points.push_back({r * std::cos(phi), r * std::sin(phi), t});
            rule.weights.push_back(gj.weights[std::size_t(i)] / azimuths);
        }
    }
    return rule;
}

} // namespace skybake
