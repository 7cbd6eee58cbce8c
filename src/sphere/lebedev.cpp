// Lebedev V. I., Laikov D. N. A quadrature formula for the sphere of the 131st
// algebraic order of accuracy. Doklady Mathematics 59(3), 1999, 477-481.
//
// Each rule is a union of octahedral orbits (the 48-element group of the cube,
// with inversion). This file generates the points of each orbit from its free
// coordinates; the published coordinates and weights are in lebedev_table.cpp.
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/sphere.h"
#include "sphere/lebedev_table.h"

namespace skybake {

namespace {

using sphere_detail::OrbitKind;

// Appends every distinct point (±p[i], ±p[j], ±p[k]) over the permutations (i, j, k)
// of (0, 1, 2): the orbit of p under the full octahedral group.
void add_orbit(SphereRule& rule, double a, double b, double c, double weight) {
    static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    const double p[3] = {a, b, c};
    const std::size_t first = rule.points.size();
    for (const auto& perm : kPerm) {
        for (int signs = 0; signs < 8; ++signs) {
            glm::dvec3 q;
            bool skip = false;
            for (int axis = 0; axis < 3; ++axis) {
                const double value = p[perm[axis]];
                const bool negative = (signs >> axis) & 1;
                if (negative && value == 0.0)
                    skip = true; // −0 is the same point as +0
                q[axis] = negative ? -value : value;
            }
            if (skip)
                continue;
            bool seen = false;
            for (std::size_t i = first; i < rule.points.size() && !seen; ++i)
                seen = rule.points[i] == q;
            if (!seen) {
                rule.points.push_back(q);
                rule.weights.push_back(weight);
            }
        }
    }
}

SphereRule build(const sphere_detail::LebedevRuleInfo& info) {
    SphereRule rule;
    rule.kind = RuleKind::Lebedev;
    rule.precision = info.precision;
    rule.spec = fmt::format("lebedev:{}", info.points);
    rule.points.reserve(std::size_t(info.points));
    rule.weights.reserve(std::size_t(info.points));
    for (int i = 0; i < info.orbit_count; ++i) {
        const sphere_detail::LebedevOrbit& o = sphere_detail::kLebedevOrbits[info.first_orbit + i];
        switch (o.kind) {
        case OrbitKind::A1: add_orbit(rule, 1.0, 0.0, 0.0, o.v); break;
        case OrbitKind::A2: add_orbit(rule, 0.0, std::sqrt(0.5), std::sqrt(0.5), o.v); break;
        case OrbitKind::A3: {
            const double t = std::sqrt(1.0 / 3.0);
            add_orbit(rule, t, t, t, o.v);
            break;
        }
        case OrbitKind::B: add_orbit(rule, o.a, o.a, std::sqrt(1.0 - 2.0 * o.a * o.a), o.v); break;
        case OrbitKind::C: add_orbit(rule, o.a, std::sqrt(1.0 - o.a * o.a), 0.0, o.v); break;
        case OrbitKind::D: add_orbit(rule, o.a, o.b, std::sqrt(1.0 - o.a * o.a - o.b * o.b), o.v); break;
        }
    }
    return rule;
}

} // namespace

const std::vector<LebedevInfo>& lebedev_rules() {
    static const std::vector<LebedevInfo> rules = [] {
        std::vector<LebedevInfo> r;
        for (int i = 0; i < sphere_detail::kLebedevRuleCount; ++i)
            r.push_back({sphere_detail::kLebedevRules[i].precision, sphere_detail::kLebedevRules[i].points});
        return r;
    }();
    return rules;
}

SphereRule lebedev_rule_by_precision(int precision) {
    for (int i = 0; i < sphere_detail::kLebedevRuleCount; ++i)
        if (sphere_detail::kLebedevRules[i].precision == precision)
            return build(sphere_detail::kLebedevRules[i]);
    throw Error(fmt::format("no Lebedev rule has precision {}; precisions are 3 to 31 in steps of 2, then 35 to 131 "
                            "in steps of 6",
                            precision),
                "lebedev:pP");
}

SphereRule lebedev_rule_by_points(int points) {
    for (int i = 0; i < sphere_detail::kLebedevRuleCount; ++i)
        if (sphere_detail::kLebedevRules[i].points == points)
            return build(sphere_detail::kLebedevRules[i]);
    throw Error(fmt::format("no Lebedev rule has {} points; run 'skybake sphere list' for the 32 rules", points),
                "lebedev:N");
}

} // namespace skybake
