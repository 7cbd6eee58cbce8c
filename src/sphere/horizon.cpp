// The horizon rule: a product rule split at y = 0, for functions with a step
// at the horizon (a sky over the dark ground). Gauss–Legendre in y on each
// side (gauss_jacobi.cpp with a = 0) times the midpoint rule in φ, which is
// exact for trigonometric polynomials of degree < m (Stroud 1971, ch. 8).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/sphere.h"
#include "sphere/gauss_jacobi.h"

namespace skybake {

SphereRule horizon_rule(int n, int m) {
    if (n < 1 || n > 512)
        throw Error(fmt::format("the horizon rule needs 1 to 512 nodes in y per side, got {}", n), "horizon:NxM");
    if (m < 1 || m > 4096)
        throw Error(fmt::format("the horizon rule needs 1 to 4096 azimuths, got {}", m), "horizon:NxM");
    const sphere::GaussRule1D gl = sphere::gauss_jacobi_unit(n, 0.0); // on (0, 1), weights sum to 1
    SphereRule rule;
    rule.kind = RuleKind::Horizon;
    rule.precision = std::min(2 * n - 1, m - 1);
    rule.spec = fmt::format("horizon:{}x{}", n, m);
    rule.points.reserve(2 * std::size_t(n) * std::size_t(m));
    rule.weights.reserve(rule.points.capacity());
    const double pi = 3.141592653589793;
    for (const double side : {1.0, -1.0})
        for (int i = 0; i < n; ++i) {
            const double y = side * gl.nodes[std::size_t(i)];
            const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
            for (int j = 0; j < m; ++j) {
                const double phi = 2.0 * pi * (j + 0.5) / m;
                rule.points.push_back({r * std::cos(phi), y, r * std::sin(phi)});
                rule.weights.push_back(0.5 * gl.weights[std::size_t(i)] / m); // each side is half the sphere
            }
        }
    return rule;
}

} // namespace skybake
