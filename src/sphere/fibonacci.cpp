// Spherical Fibonacci point sets: Swinbank R., Purser R. J. Fibonacci grids: a
// novel approach to global modelling. Q. J. R. Meteorol. Soc. 132, 2006; and
// Marques R. et al. Spherical Fibonacci point sets for illumination integrals.
// Computer Graphics Forum 32(8), 2013.
#include <algorithm>
#include <cmath>

#include "skybake/error.h"
#include "skybake/sphere.h"

namespace skybake {

SphereRule fibonacci_rule(int n) {
    if (n < 1)
        throw Error("a Fibonacci rule needs at least one point", "fibonacci:N");
    SphereRule rule;
    rule.kind = RuleKind::Fibonacci;
    rule.spec = "fibonacci:" + std::to_string(n);
    rule.points.resize(std::size_t(n));
    const double golden = (1.0 + std::sqrt(5.0)) / 2.0;
    const double two_pi = 6.283185307179586;
    for (int k = 0; k < n; ++k) {
        const double z = 1.0 - (2.0 * k + 1.0) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        // φ_k = 2π k / Φ, reduced mod 2π on the fraction to keep precision for large k.
        const double frac = k / golden - std::floor(k / golden);
        const double phi = two_pi * frac;
        rule.points[std::size_t(k)] = {r * std::cos(phi), r * std::sin(phi), z};
    }
    rule.weights.assign(std::size_t(n), 1.0 / n);
    return rule;
}

} // namespace skybake
