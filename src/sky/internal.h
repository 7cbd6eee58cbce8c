// Internal glue between the public sky API and the shared CPU/GPU maths
// (the parts other modules share are in sky/device.h).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/exponential.hpp>
#include <glm/geometric.hpp>

#include "skybake/sky.h"
#include "sky/device.h"

namespace skybake::sky {

// Altitude of the point origin + t dir, from |p|² − R0² without cancellation.
struct RayAltitude {
    double R0, h0, r0, mu; // origin altitude, radius and cosine to its vertical
    RayAltitude(double R0_, const glm::dvec3& origin, const glm::dvec3& dir) : R0(R0_) {
        r0 = glm::length(origin);
        h0 = r0 - R0; // origin altitudes are small or the origin is far: fine in double
        mu = glm::dot(origin, dir) / r0;
    }
    double operator()(double t) const {
        const double d2 = h0 * (2.0 * R0 + h0) + t * (t + 2.0 * r0 * mu);
        return d2 / (std::sqrt(R0 * R0 + std::max(d2, -R0 * R0)) + R0);
    }
    // Distance to the lowest point of the line (the tangent point).
    double tangent() const { return -r0 * mu; }
};

// A quarter of the sharpest density profile's length scale: the first panel
// of the quadratures' graded breakpoints.
double profile_scale(const Atmosphere& atmosphere);

// Exact in-scattered radiance (1/sr, per unit irradiance) along the segment
// from `origin_km` in unit direction `dir` for length_km, with unit sun
// direction `sun`, all in a planet-centred frame. Also returns the segment's
// transmittance when `transmittance` is not null.
glm::dvec3 inscatter_exact(const Atmosphere& atmosphere, const glm::dvec3& origin_km, const glm::dvec3& dir,
                           double length_km, const glm::dvec3& sun, double tolerance,
                           glm::dvec3* transmittance = nullptr);

// Exact transmittance of sunlight reaching point_km (0 in the planet's shadow).
glm::dvec3 sun_transmittance_exact(const Atmosphere& atmosphere, const glm::dvec3& point_km, const glm::dvec3& sun);

// ∫_a^b extinction dt along origin_km + t dir (per channel), by adaptive
// quadrature to the relative tolerance.
glm::dvec3 optical_depth_exact(const Atmosphere& atmosphere, const glm::dvec3& origin_km, const glm::dvec3& dir,
                               double a_km, double b_km, double tolerance);

// Length of the view ray inside the atmosphere from origin_km along dir: the
// entry distance (0 inside) and the exit or ground distance. False if it misses.
bool atmosphere_segment(const Atmosphere& atmosphere, const glm::dvec3& origin_km, const glm::dvec3& dir,
                        double& enter_km, double& exit_km, bool& hits_ground);

} // namespace skybake::sky
