// Bruneton E. Precomputed Atmospheric Scattering (2017 reference
// implementation), "Transmittance": T(r, μ) to the top over
// x_r = ρ/H, x_μ = (d − d_min)/(d_max − d_min), with ρ = sqrt(r² − R0²),
// H = sqrt(Rt² − R0²), d the distance to the top, d_min = Rt − r, d_max = ρ + H.
// Stored as optical depth (closer to linear than T), in double.
#include "sky/transmittance_table.h"

#include <algorithm>
#include <cassert>

#include <glm/common.hpp>
#include <glm/exponential.hpp>

#include "core/parallel.h"

namespace skybake::sky {

glm::dvec3 extinction_at_altitude(const Atmosphere& atm, double h) {
    glm::dvec3 e(0.0);
    for (const AtmosphereComponent& c : atm.components)
        e += c.extinction_per_km * relative_density(c, h);
    return e;
}

glm::dvec3 scattering_at_altitude(const Atmosphere& atm, double h) {
    glm::dvec3 e(0.0);
    for (const AtmosphereComponent& c : atm.components)
        e += c.scattering_per_km * relative_density(c, h);
    return e;
}

double sharpest_scale_height(const Atmosphere& atm) {
    double s = atm.components.at(0).scale_height_km;
    for (const AtmosphereComponent& c : atm.components)
        if (c.profile == DensityProfile::Exponential)
            s = std::min(s, c.scale_height_km);
    return s;
}

TransmittanceTable::TransmittanceTable(const Atmosphere& atm, int nr, int nmu, int points)
    : R0_(atm.planet_radius_km), Rt_(atm.top_radius_km), H_(std::sqrt(Rt_ * Rt_ - R0_ * R0_)), nr_(nr), nmu_(nmu) {
    assert(nr >= 2 && nmu >= 2);
    depth_.resize(std::size_t(nr) * std::size_t(nmu));
    const double scale = sharpest_scale_height(atm);
    parallel_for(depth_.size(), 64, [&](std::size_t b, std::size_t e) {
        for (std::size_t idx = b; idx < e; ++idx) {
            const int i = int(idx) / nmu, j = int(idx) % nmu;
            const double rho = H_ * double(i) / double(nr - 1);
            const double r = std::sqrt(rho * rho + R0_ * R0_);
            const double dmin = Rt_ - r, dmax = rho + H_;
            const double d = dmin + double(j) / double(nmu - 1) * (dmax - dmin);
            const double mu = d <= 0.0 ? 1.0 : std::clamp((H_ * H_ - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
            glm::dvec3 tau(0.0);
            for_each_ray_midpoint(R0_, scale, r, mu, d, points, [&](double t, double dt) {
                tau += extinction_at_altitude(atm, ray_radius(r, mu, t) - R0_) * dt;
            });
            depth_[idx] = tau;
        }
    });
}

glm::dvec3 TransmittanceTable::depth_to_top(double r, double mu) const {
    r = std::clamp(r, R0_, Rt_);
    const double rho = std::sqrt(std::max(0.0, r * r - R0_ * R0_));
    const double d = ray_top_distance(Rt_, r, mu);
    const double dmin = Rt_ - r, dmax = rho + H_;
    const double xr = rho / H_ * double(nr_ - 1);
    const double xm = std::clamp((d - dmin) / (dmax - dmin), 0.0, 1.0) * double(nmu_ - 1);
    const int i = std::min(int(xr), nr_ - 2), j = std::min(int(xm), nmu_ - 2);
    const double fr = std::min(1.0, xr - i), fm = std::min(1.0, xm - j);
    const auto at = [&](int a, int b) { return depth_[std::size_t(a) * std::size_t(nmu_) + std::size_t(b)]; };
    return (1.0 - fr) * ((1.0 - fm) * at(i, j) + fm * at(i, j + 1)) + fr * ((1.0 - fm) * at(i + 1, j) + fm * at(i + 1, j + 1));
}

glm::dvec3 TransmittanceTable::between(double r, double mu, double d, bool ground_ray) const {
    const double rd = std::clamp(ray_radius(r, mu, d), R0_, Rt_);
    const double mud = std::clamp((r * mu + d) / std::max(rd, 1e-9), -1.0, 1.0);
    const glm::dvec3 tau = ground_ray ? depth_to_top(rd, -mud) - depth_to_top(r, -mu) : depth_to_top(r, mu) - depth_to_top(rd, mud);
    return glm::exp(-glm::max(tau, glm::dvec3(0.0)));
}

glm::dvec3 TransmittanceTable::sun(double r, double mu_s) const {
    if (ray_ground_distance(R0_, r, mu_s) >= 0.0)
        return glm::dvec3(0.0);
    return glm::exp(-depth_to_top(r, mu_s));
}

} // namespace skybake::sky
