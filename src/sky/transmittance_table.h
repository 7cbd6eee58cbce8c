// Transmittance to the top of the atmosphere, T(r, μ), tabulated in double
// precision over Bruneton's (2017) parameterisation, and the ray quadrature
// shared by the multiple-scattering precomputations (scattering_orders.cpp,
// multiple_scattering_lut.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/sky.h"

namespace skybake::sky {

// Midpoints of [0, length] along a ray from radius r with cosine mu: n points
// graded geometrically away from the ray's lowest point, where the density
// peaks (the double twin of march_view_ray in sky_hd.h). fn(t, dt).
template <class Fn>
void for_each_ray_midpoint(double R0, double scale_height, double r, double mu, double length, int n, Fn&& fn) {
    if (!(length > 0.0) || n <= 0)
        return;
    double t_low = std::clamp(-r * mu, 0.0, length);
    const double r_low = std::sqrt(std::max(R0 * R0, r * r + t_low * t_low + 2.0 * r * mu * t_low));
    const double mu_low = std::abs(r * mu + t_low) / r_low;
    const double s = scale_height / (mu_low + std::sqrt(2.0 * scale_height / r_low));
    const double before = t_low, after = length - t_low;
    const double wb = std::log1p(before / s), wa = std::log1p(after / s);
    int nb = int(double(n) * wb / (wb + wa) + 0.5);
    if (before > 0.0 && nb < 1)
        nb = 1;
    if (after > 0.0 && nb > n - 1)
        nb = n - 1;
    const auto side = [&](double D, double dir, int m) {
        if (m <= 0 || !(D > 0.0))
            return;
        const double w = std::log1p(D / s);
        for (int j = 0; j < m; ++j) {
            const double e = std::exp(w * (double(j) + 0.5) / double(m));
            fn(t_low + dir * s * (e - 1.0), s * w * e / double(m));
        }
    };
    side(before, -1.0, nb);
    side(after, 1.0, n - nb);
}

// Radius at distance t along a ray from radius r with cosine mu.
inline double ray_radius(double r, double mu, double t) { return std::sqrt(std::max(0.0, r * r + t * t + 2.0 * r * mu * t)); }

// Distance to the ground along (r, mu), or a negative value when the ray misses it.
inline double ray_ground_distance(double R0, double r, double mu) {
    const double disc = r * r * (mu * mu - 1.0) + R0 * R0;
    if (!(mu < 0.0) || disc < 0.0)
        return -1.0;
    return std::max(0.0, -r * mu - std::sqrt(disc));
}

// Distance to the top (radius Rt ≥ r) along (r, mu).
inline double ray_top_distance(double Rt, double r, double mu) {
    return std::max(0.0, -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + Rt * Rt)));
}

class TransmittanceTable {
public:
    // Optical depths integrated with `points` graded midpoints per node.
    explicit TransmittanceTable(const Atmosphere& atmosphere, int radius_nodes = 64, int cosine_nodes = 256,
                                int points = 128);

    // Optical depth (per channel) from radius r towards cosine mu to the top;
    // the ray must not meet the ground.
    glm::dvec3 depth_to_top(double r, double mu) const;
    // Transmittance over the first d km of the ray (r, mu); ground_ray: the
    // ray meets the ground (then d must not pass it).
    glm::dvec3 between(double r, double mu, double d, bool ground_ray) const;
    // Sunlight reaching radius r with the sun at cosine mu_s: 0 in the planet's shadow.
    glm::dvec3 sun(double r, double mu_s) const;

    double R0() const { return R0_; }
    double Rt() const { return Rt_; }

private:
    double R0_, Rt_, H_;
    int nr_, nmu_;
    std::vector<glm::dvec3> depth_;
};

// Σ_k extinction_k ρ_k(h) and Σ_k scattering_k ρ_k(h), per km.
glm::dvec3 extinction_at_altitude(const Atmosphere& atmosphere, double altitude_km);
glm::dvec3 scattering_at_altitude(const Atmosphere& atmosphere, double altitude_km);
// The smallest exponential scale height (the sharpest profile), for the ray quadrature.
double sharpest_scale_height(const Atmosphere& atmosphere);

} // namespace skybake::sky
