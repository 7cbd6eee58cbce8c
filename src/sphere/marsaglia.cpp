// Marsaglia G. Choosing a point from the surface of a sphere. Ann. Math. Stat.
// 43(2), 1972, 645-646 -- the Monte Carlo rule of seed 002, section "Spherical
// cubature", kind 1.
//
// Random numbers: splitmix64 (Steele, Lea & Flood 2014) turned into doubles with
// 53 random bits, so the points are the same on every platform and compiler.
#include <cmath>

#include "skybake/error.h"
#include "skybake/sphere.h"
#include "sphere/random_rotation.h"

namespace skybake {

SphereRule marsaglia_rule(int n, std::uint64_t seed) {
    if (n < 1)
        throw Error("a Monte Carlo rule needs at least one point", "mc:N");
    SphereRule rule;
    rule.kind = RuleKind::MonteCarlo;
    rule.spec = seed == 1 ? "mc:" + std::to_string(n) : "mc:" + std::to_string(n) + ",seed=" + std::to_string(seed);
    rule.points.reserve(std::size_t(n));
    std::uint64_t state = sphere::splitmix64(seed);
    auto uniform_pm1 = [&] { // uniform on (−1, 1)
        state += 0x9e3779b97f4a7c15ull;
        return 2.0 * sphere::unit_double(sphere::splitmix64(state)) - 1.0;
    };
    while (int(rule.points.size()) < n) {
        const double x1 = uniform_pm1(), x2 = uniform_pm1();
        const double s = x1 * x1 + x2 * x2;
        if (s >= 1.0)
            continue;
        const double r = 2.0 * std::sqrt(1.0 - s);
        rule.points.push_back({x1 * r, x2 * r, 1.0 - 2.0 * s});
    }
    rule.weights.assign(std::size_t(n), 1.0 / n);
    return rule;
}

} // namespace skybake
