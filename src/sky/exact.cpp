// Exact single-scattering reference (Nishita et al. 1993, eq. for I_v with
// the sun's and the viewer's attenuation), in double precision: nested
// adaptive Gauss–Kronrod quadrature along the true ray geometry, the ground
// honoured (a ray that meets it ends there; sunlight through it is zero).
// It is the yardstick for the seed's tables and marching sum.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "sky/internal.h"
#include "sky/quadrature.h"

namespace skybake {

namespace sky {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

glm::dvec3 extinction_at(const Atmosphere& atm, double h) {
    glm::dvec3 e(0.0);
    for (const AtmosphereComponent& c : atm.components)
        e += c.extinction_per_km * relative_density(c, h);
    return e;
}

} // namespace

double profile_scale(const Atmosphere& atm) {
    double s = atm.top_radius_km - atm.planet_radius_km;
    for (const AtmosphereComponent& c : atm.components) {
        if (c.profile == DensityProfile::Exponential)
            s = std::min(s, c.scale_height_km);
        if (c.profile == DensityProfile::Tent)
            s = std::min(s, c.tent_half_width_km);
    }
    return 0.25 * s;
}

// ∫_a^b extinction(x(t)) dt along origin + t dir: optical depth per channel.
glm::dvec3 optical_depth_exact(const Atmosphere& atm, const glm::dvec3& origin, const glm::dvec3& dir, double a,
                               double b, double tolerance) {
    if (!(b > a))
        return glm::dvec3(0.0);
    const RayAltitude alt(atm.planet_radius_km, origin, dir);
    const auto f = [&](double t) { return extinction_at(atm, alt(t)); };
    const auto pts = graded_breakpoints(a, b, {a, b, alt.tangent()}, profile_scale(atm));
    return integrate_adaptive(f, pts, tolerance, 1e-15);
}

bool atmosphere_segment(const Atmosphere& atm, const glm::dvec3& origin, const glm::dvec3& dir, double& enter,
                        double& exit, bool& hits_ground) {
    const double R0 = atm.planet_radius_km, Rt = atm.top_radius_km;
    const double r = glm::length(origin);
    const double b = glm::dot(origin, dir); // r·mu
    hits_ground = false;
    enter = 0.0;
    if (r > Rt) {
        const double disc = b * b - (r - Rt) * (r + Rt);
        if (b >= 0.0 || disc <= 0.0)
            return false;
        enter = -b - std::sqrt(disc);
    }
    const double disc_g = b * b - (r - R0) * (r + R0);
    if (b < 0.0 && disc_g > 0.0) {
        const double g = -b - std::sqrt(disc_g);
        if (g >= enter) {
            exit = g;
            hits_ground = true;
            return true;
        }
    }
    const double disc_t = b * b - (r - Rt) * (r + Rt);
    exit = -b + std::sqrt(std::max(0.0, disc_t));
    return exit > enter;
}

glm::dvec3 sun_transmittance_exact(const Atmosphere& atm, const glm::dvec3& p, const glm::dvec3& sun) {
    double enter, exit;
    bool ground;
    if (!atmosphere_segment(atm, p, sun, enter, exit, ground))
        return glm::dvec3(1.0);
    if (ground)
        return glm::dvec3(0.0);
    return glm::exp(-optical_depth_exact(atm, p, sun, enter, exit, 1e-10));
}

glm::dvec3 inscatter_exact(const Atmosphere& atm, const glm::dvec3& origin, const glm::dvec3& dir, double length,
                           const glm::dvec3& sun, double tolerance, glm::dvec3* transmittance) {
    if (transmittance)
        *transmittance = glm::dvec3(1.0);
    if (!(length > 0.0))
        return glm::dvec3(0.0);
    const double R0 = atm.planet_radius_km;
    const double mu_vs = glm::dot(dir, sun);
    std::vector<glm::dvec3> scatter;
    for (const AtmosphereComponent& c : atm.components)
        scatter.push_back(c.scattering_per_km * phase_function(c.phase, c.phase_g, mu_vs));
    const RayAltitude alt(R0, origin, dir);
    const double inner_tol = std::min(1e-9, tolerance * 1e-2);

    const auto f = [&](double v) -> glm::dvec3 {
        const glm::dvec3 x = origin + v * dir;
        const glm::dvec3 ts = sun_transmittance_exact(atm, x, sun);
        if (ts == glm::dvec3(0.0))
            return glm::dvec3(0.0);
        const double h = alt(v);
        glm::dvec3 w(0.0);
        for (std::size_t k = 0; k < atm.components.size(); ++k)
            w += scatter[k] * relative_density(atm.components[k], h);
        const glm::dvec3 tv = glm::exp(-optical_depth_exact(atm, origin, dir, 0.0, v, inner_tol));
        return w * ts * tv;
    };

    // Break at the planet's shadow boundary: |x⊥|² = R0², x⊥ the part of x
    // across the sun direction.
    std::vector<double> extra;
    const glm::dvec3 op = origin - glm::dot(origin, sun) * sun;
    const glm::dvec3 dp = dir - glm::dot(dir, sun) * sun;
    const double qa = glm::dot(dp, dp), qb = glm::dot(op, dp), qc = glm::dot(op, op) - R0 * R0;
    if (qa > 1e-30) {
        const double disc = qb * qb - qa * qc;
        if (disc > 0.0) {
            extra.push_back((-qb - std::sqrt(disc)) / qa);
            extra.push_back((-qb + std::sqrt(disc)) / qa);
        }
    }
    const auto pts = graded_breakpoints(0.0, length, {0.0, length, alt.tangent()}, profile_scale(atm), extra);
    const glm::dvec3 result = integrate_adaptive(f, pts, tolerance, 1e-300);
    if (transmittance)
        *transmittance = glm::exp(-optical_depth_exact(atm, origin, dir, 0.0, length, 1e-10));
    return result;
}

} // namespace sky

double optical_length_exact(const Atmosphere& atm, int k, double altitude_km, double mu) {
    assert(k >= 0 && k < int(atm.components.size()));
    const double R0 = atm.planet_radius_km;
    const double r = R0 + altitude_km;
    mu = std::clamp(mu, -1.0, 1.0);
    const glm::dvec3 origin(0.0, 0.0, r);
    const glm::dvec3 dir(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
    double enter, exit;
    bool ground;
    if (!sky::atmosphere_segment(atm, origin, dir, enter, exit, ground))
        return 0.0;
    if (ground)
        return sky::kInf;
    const AtmosphereComponent& comp = atm.components[std::size_t(k)];
    const sky::RayAltitude alt(R0, origin, dir);
    const auto f = [&](double t) { return glm::dvec3(relative_density(comp, alt(t)), 0.0, 0.0); };
    double scale = atm.top_radius_km - R0;
    if (comp.profile == DensityProfile::Exponential)
        scale = comp.scale_height_km;
    if (comp.profile == DensityProfile::Tent)
        scale = comp.tent_half_width_km;
    const auto pts = sky::graded_breakpoints(enter, exit, {enter, exit, alt.tangent()}, 0.25 * scale);
    return sky::integrate_adaptive(f, pts, 1e-12, 1e-300).x;
}

} // namespace skybake
