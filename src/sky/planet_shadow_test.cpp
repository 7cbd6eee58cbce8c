// planet_shadow_interval() (src/sky/planet_shadow_hd.h) against a brute-force
// march of the same ray in 3D, and against closed cases.
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "core/random.h"
#include "sky/planet_shadow_hd.h"
#include "skybake/sky.h"

namespace skybake::sky {
namespace {

constexpr double kR = 6360.0;

bool in_shadow(const glm::dvec3& p, const glm::dvec3& s) {
    const double a = glm::dot(p, s);
    return a < 0.0 && glm::dot(p - a * s, p - a * s) < kR * kR;
}

TEST(PlanetShadow, MatchesABruteForceMarchOfTheRay) {
    SplitMix64 rng{0x5bad0e0u};
    int shadowed = 0, lit = 0;
    for (int n = 0; n < 4000; ++n) {
        // A random observer altitude (0 to 100 km), view and sun.
        const double h = 100.0 * rng.uniform() * rng.uniform();
        const double r = kR + h;
        auto unit = [&] {
            const double z = 2.0 * rng.uniform() - 1.0, phi = 2.0 * M_PI * rng.uniform();
            return glm::dvec3(std::sqrt(1.0 - z * z) * std::cos(phi), std::sqrt(1.0 - z * z) * std::sin(phi), z);
        };
        const glm::dvec3 up(0.0, 0.0, 1.0), v = unit(), s = unit();
        const double mu = v.z, nu = glm::dot(v, s), mu_s = s.z;
        const ShadowInterval<double> got = planet_shadow_interval(r, kR, mu, nu, mu_s);
        // March 0 to 4000 km in 0.05 km steps: the first and last shadowed step.
        const double step = 0.05, reach = 4000.0;
        double first = -1.0, last = -1.0;
        for (double t = 0.0; t <= reach; t += step)
            if (in_shadow(r * up + t * v, s)) {
                if (first < 0.0)
                    first = t;
                last = t;
            }
        if (first < 0.0) {
            ++lit;
            EXPECT_TRUE(got.t0 > got.t1 || got.t0 > reach - step) << n << ": " << got.t0 << " " << got.t1;
            continue;
        }
        ++shadowed;
        ASSERT_LE(got.t0, got.t1) << n;
        EXPECT_NEAR(got.t0, first, step) << n;
        EXPECT_NEAR(std::min(got.t1, reach), last, step) << n;
        // One interval: every step between is in shadow too (convexity).
        for (double t = first; t <= last; t += 7.3)
            EXPECT_TRUE(in_shadow(r * up + t * v, s)) << n << " at " << t;
    }
    // Both cases occur often enough to mean something.
    EXPECT_GT(shadowed, 1000);
    EXPECT_GT(lit, 1000);
}

TEST(PlanetShadow, ClosedCases) {
    const double r = kR + 10.0;
    // Midnight, looking straight up (along the axis): in shadow all the way.
    ShadowInterval<double> s = planet_shadow_interval(r, kR, 1.0, -1.0, -1.0);
    EXPECT_EQ(s.t0, 0.0);
    EXPECT_EQ(s.t1, std::numeric_limits<double>::infinity());
    // Noon: no shadow anywhere along any ray that stays up.
    s = planet_shadow_interval(r, kR, 1.0, 1.0, 1.0);
    EXPECT_GT(s.t0, s.t1);
    // The sun on the horizon, looking at the zenith: the observer sits just
    // inside the terminator plane's lit side (p·s = 0 at t = 0), so nothing.
    s = planet_shadow_interval(r, kR, 1.0, 0.0, 0.0);
    EXPECT_GT(s.t0, s.t1);
    // Sun 10° below the horizon, looking up: the ray leaves the cylinder where
    // its distance from the axis reaches R: (r + t) sin(100°) = R... here the
    // axis distance is (r + t)·sin θ with θ the angle to the sun's axis.
    const double below = -std::sin(10.0 * M_PI / 180.0); // μs
    s = planet_shadow_interval(r, kR, 1.0, below, below);
    const double sin_theta = std::sqrt(1.0 - below * below);
    EXPECT_EQ(s.t0, 0.0);
    EXPECT_NEAR(s.t1, kR / sin_theta - r, 1e-6);
}

} // namespace
} // namespace skybake::sky
