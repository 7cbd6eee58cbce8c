// Seed 000 section IV, the colour of a surface seen through the air, against
// an exact reference built here: a uniform shell (constant density) of one
// scattering gas, where every optical length is β times a chord length and
// the in-scatter integral is one-dimensional.
#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/sky.h"

using namespace skybake;

namespace {

constexpr double kR0 = 6360.0, kTop = 6420.0, kBeta = 0.01; // per km: τ = 0.6 straight up

// The first component must be exponential (it is the density coordinate); it
// is given no scattering and no extinction, so the light sees only the shell.
Atmosphere uniform_shell() {
    Atmosphere a;
    a.name = "uniform shell";
    a.planet_radius_km = kR0;
    a.top_radius_km = kTop;
    AtmosphereComponent coordinate;
    coordinate.name = "coordinate";
    coordinate.scale_height_km = 8.0;
    AtmosphereComponent gas;
    gas.name = "gas";
    gas.profile = DensityProfile::Constant;
    gas.scattering_per_km = gas.extinction_per_km = glm::dvec3(kBeta, 2 * kBeta, 3 * kBeta);
    gas.phase = PhaseFunction::Rayleigh;
    a.components = {coordinate, gas};
    return a;
}

// Distance from p along unit d to the sphere of radius r (p inside it).
double to_sphere(const glm::dvec3& p, const glm::dvec3& d, double r) {
    const double b = glm::dot(p, d), c = glm::dot(p, p) - r * r;
    return -b + std::sqrt(b * b - c);
}

glm::dvec3 exp3(const glm::dvec3& x) {
    return {std::exp(x.x), std::exp(x.y), std::exp(x.z)};
}

struct Scene {
    glm::dvec3 observer, surface, sun;
};

// Observer 1 km up, looking down at a ground point 20 km away; sun 40° up.
Scene scene() {
    const double phi = 20.0 / kR0; // 20 km of arc
    const glm::dvec3 surface(kR0 * std::sin(phi), kR0 * std::cos(phi), 0.0);
    const glm::dvec3 observer(0.0, kR0 + 1.0, 0.0);
    const double e = 40.0 * M_PI / 180.0;
    return {observer, surface, glm::normalize(glm::dvec3(std::cos(e) * 0.3, std::sin(e), std::cos(e) * 0.954))};
}

} // namespace

TEST(SurfaceLight, ReflectedSunlightMatchesTheUniformShell) {
    const SkyModel model(uniform_shell());
    const Scene s = scene();
    const glm::dvec3 albedo(0.3, 0.5, 0.7);
    const SurfaceLight l = surface_light(model, s.observer, s.surface, s.sun, albedo);
    const glm::dvec3 beta = glm::dvec3(kBeta, 2 * kBeta, 3 * kBeta);
    const double view = glm::length(s.surface - s.observer);
    const glm::dvec3 n = glm::normalize(s.surface);
    const double cos_sun = glm::dot(n, s.sun);
    ASSERT_GT(cos_sun, 0.5);
    // Lambert: C cos θ / π, times the sun's path to the surface and the view path.
    const glm::dvec3 t_view = exp3(-beta * view);
    const glm::dvec3 expect = albedo * (cos_sun / M_PI) * exp3(-beta * to_sphere(s.surface, s.sun, kTop)) * t_view;
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(l.transmittance_exact[c], t_view[c], 1e-9 * t_view[c]) << c;
        EXPECT_NEAR(l.reflected_exact[c], expect[c], 1e-8 * expect[c]) << c;
        // The tables path: the seed's optical-length tables at their default
        // resolution, interpolated (measured 0.1–0.3%, the most in blue, where
        // τ ≈ 2.4 over both paths).
        EXPECT_NEAR(l.reflected_tables[c], expect[c], 5e-3 * expect[c]) << c;
    }
    // A surface facing away from the sun reflects nothing.
    const SurfaceLight dark = surface_light(model, s.observer, s.surface, -s.sun, albedo);
    EXPECT_EQ(dark.reflected_exact, glm::dvec3(0.0));
    EXPECT_EQ(dark.reflected_tables, glm::dvec3(0.0));
}

TEST(SurfaceLight, InscatterMatchesAnIndependentQuadrature) {
    // I = β p(μ) ∫_0^D exp(−β t) exp(−β ℓ_sun(x(t))) dt per unit irradiance,
    // with ℓ_sun the chord from x(t) to the top along the sun: Simpson's rule
    // on 20,000 intervals (error ~1e-12 here).
    const SkyModel model(uniform_shell());
    const Scene s = scene();
    const SurfaceLight l = surface_light(model, s.observer, s.surface, s.sun, glm::dvec3(0.2));
    const glm::dvec3 beta = glm::dvec3(kBeta, 2 * kBeta, 3 * kBeta);
    const double D = glm::length(s.surface - s.observer);
    const glm::dvec3 V = (s.surface - s.observer) / D;
    const double mu = glm::dot(V, s.sun);
    const double phase = 3.0 / (16.0 * M_PI) * (1.0 + mu * mu);
    const int n = 20000;
    glm::dvec3 sum(0.0);
    for (int i = 0; i <= n; ++i) {
        const double t = D * i / n;
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * exp3(-beta * (t + to_sphere(s.observer + t * V, s.sun, kTop)));
    }
    const glm::dvec3 expect = beta * phase * sum * (D / n / 3.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(l.inscatter_exact[c], expect[c], 1e-6 * expect[c]) << c;
        // The seed's difference I(observer) − I(probe): the probe on the ground
        // looks into the ground and sees nothing, so the difference is the
        // whole segment's in-scatter, to the tables' and the sum's accuracy.
        EXPECT_NEAR(l.inscatter_seed[c], expect[c], 2e-2 * expect[c]) << c;
    }
}
