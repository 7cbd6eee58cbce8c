// The input space of the sky function (seed 000, section III): the cosines
// (cos α0, cos β0, cos θ0) in [−1, 1]³ and the density ρ0 in (0, 1]. Three
// cosines belong to three real unit vectors exactly when their Gram matrix
//     | 1 a c |
//     | a 1 b |
//     | c b 1 |
// is positive semi-definite, i.e. its determinant 1 + 2abc − a² − b² − c² ≥ 0
// (the 2×2 minors 1 − a² etc. are then non-negative too).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "core/parallel.h"
#include "core/random.h"
#include "skybake/error.h"
#include "skybake/sky.h"

namespace skybake {

double cosine_triple_determinant(double a, double b, double c) {
    return 1.0 + 2.0 * a * b * c - a * a - b * b - c * c;
}

bool is_valid_cosine_triple(double a, double b, double c, double tolerance) {
    if (!(std::isfinite(a) && std::isfinite(b) && std::isfinite(c)))
        return false;
    if (std::abs(a) > 1.0 || std::abs(b) > 1.0 || std::abs(c) > 1.0)
        return false;
    return cosine_triple_determinant(a, b, c) >= -tolerance;
}

bool is_valid_sky_sample(const SkySample& s, double tolerance) {
    return is_valid_cosine_triple(s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, tolerance) &&
           std::isfinite(s.density) && s.density > 0.0f && s.density <= 1.0f;
}

void check_sky_sample(const SkySample& s, const std::string& where) {
    const double a = s.cos_view_zenith, b = s.cos_view_sun, c = s.cos_sun_zenith;
    if (!(std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && std::isfinite(s.density)))
        throw Error("every value must be a finite number", where);
    if (std::abs(a) > 1.0 || std::abs(b) > 1.0 || std::abs(c) > 1.0)
        throw Error("cosines must lie in [-1, 1]", where);
    if (!(s.density > 0.0f && s.density <= 1.0f))
        throw Error(fmt::format("density {} is outside (0, 1]", s.density), where);
    const double det = cosine_triple_determinant(a, b, c);
    if (det < -1e-6)
        throw Error(fmt::format("impossible cosine triple ({}, {}, {}): no three directions have these angles "
                                "(1 + 2abc - a^2 - b^2 - c^2 = {:.3g} < 0)",
                                a, b, c, det),
                    where);
}

namespace {

using SplitMix = SplitMix64;

} // namespace

std::vector<SkySample> draw_sky_samples(std::size_t count, std::uint64_t seed) {
    std::vector<SkySample> out(count);
    parallel_for(count, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            SplitMix rng{seed * 0xD1B54A32D192ED03ull + i * 0x9E3779B97F4A7C15ull};
            rng.next();
            for (;;) {
                const double a = 2.0 * rng.uniform() - 1.0;
                const double b = 2.0 * rng.uniform() - 1.0;
                const double c = 2.0 * rng.uniform() - 1.0;
                const double rho = 1.0 - rng.uniform(); // (0, 1]
                SkySample s{float(a), float(b), float(c), float(rho)};
                if (s.density > 0.0f && cosine_triple_determinant(s.cos_view_zenith, s.cos_view_sun,
                                                                  s.cos_sun_zenith) >= 0.0) {
                    out[i] = s;
                    break;
                }
            }
        }
    });
    return out;
}

std::vector<SkySample> draw_flight_samples(std::size_t count, std::uint64_t seed, const Atmosphere& atmosphere,
                                           const FlightSampling& f) {
    if (!(f.max_altitude_km > 0.0) || !(f.min_sun_elevation_deg >= -90.0 && f.min_sun_elevation_deg < 90.0))
        throw Error("the flight samples need a maximum altitude > 0 and a lowest sun elevation in [-90, 90) degrees",
                    "FlightSampling");
    const double pi = 3.14159265358979323846, lo = f.min_sun_elevation_deg * pi / 180.0;
    std::vector<SkySample> out(count);
    parallel_for(count, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            SplitMix rng{seed * 0xD1B54A32D192ED03ull + i * 0x9E3779B97F4A7C15ull + 0x5f1147ull};
            rng.next();
            for (;;) {
                const double h = f.max_altitude_km * rng.uniform();
                const double elevation = lo + (0.5 * pi - lo) * rng.uniform();
                const double cz = 2.0 * rng.uniform() - 1.0; // the view direction, uniform on the sphere
                const double phi = 2.0 * pi * rng.uniform(); // its azimuth from the sun's
                const double cs = std::sin(elevation);
                const double cvs = cz * cs + std::sqrt(std::max(0.0, (1.0 - cz * cz) * (1.0 - cs * cs))) * std::cos(phi);
                SkySample s{float(cz), float(std::clamp(cvs, -1.0, 1.0)), float(cs),
                            float(atmosphere.density_from_altitude(h))};
                if (s.density > 0.0f &&
                    cosine_triple_determinant(s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith) >= 0.0) {
                    out[i] = s;
                    break;
                }
            }
        }
    });
    return out;
}

} // namespace skybake
