// Distant light in spherical harmonics: constant, projected functions,
// equirectangular maps, and the sky (reference model or network) with the sun
// as a direct light.
//
// Sloan, Kautz & Snyder 2002 (the light as SH, rotated with the model);
// Ivanic & Ruedenberg 1996 (rotation, skybake/sh.h); Pietras & Rudnicki
// (seed 000) for the sky and the optical-length tables that give the sun's
// transmittance.
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {

namespace {

void check_order(int order) {
    if (order < 0 || order > kShMaxL)
        throw Error(fmt::format("SH order must be 0 to {}; got {}", kShMaxL, order), "order");
}

void check_rule(const SphereRule& rule) {
    if (rule.size() == 0)
        throw Error("the sphere rule has no points", "rule");
    if (rule.kind == RuleKind::Phong)
        throw Error(fmt::format("'{}' integrates against a Phong lobe; project light with a lebedev, design, "
                                "fibonacci or mc rule",
                                rule.spec),
                    "rule");
}

} // namespace

ShLight constant_light(const glm::vec3& radiance, int order) {
    check_order(order);
    ShLight l;
    l.order = order;
    l.coeffs.assign(std::size_t(sh_count(order)), glm::vec3(0.0f));
    l.coeffs[0] = radiance * float(2.0 * std::sqrt(M_PI));
    return l;
}

ShLight project_light(const std::function<glm::vec3(const glm::vec3&)>& radiance, int order, const SphereRule& rule) {
    check_order(order);
    check_rule(rule);
    const int nc = sh_count(order);
    std::vector<glm::dvec3> sum(std::size_t(nc), glm::dvec3(0.0));
    std::vector<double> y(static_cast<std::size_t>(nc));
    for (std::size_t k = 0; k < rule.size(); ++k) {
        const glm::dvec3 f = glm::dvec3(radiance(glm::vec3(rule.points[k]))) * (4.0 * M_PI * rule.weights[k]);
        sh_eval(order, rule.points[k], y.data());
        for (int i = 0; i < nc; ++i)
            sum[std::size_t(i)] += f * y[std::size_t(i)];
    }
    ShLight l;
    l.order = order;
    for (const glm::dvec3& s : sum)
        l.coeffs.emplace_back(s);
    return l;
}

// World (+y up) to the map's frame (+z up, sh.h): a proper rotation.
static glm::vec3 equirect_direction(const glm::vec3& world) {
    return {world.x, -world.z, world.y};
}

ShLight equirect_light(const Image& map, int order, const SphereRule& rule) {
    if (map.width <= 0 || map.height <= 0 || map.rgb.size() != std::size_t(map.width) * std::size_t(map.height) * 3)
        throw Error("the environment map is empty", "light");
    if (std::abs(map.width - 2 * map.height) > 1)
        throw Error(
            fmt::format("an equirectangular map is twice as wide as high; this one is {}x{}", map.width, map.height),
            "light");
    for (float v : map.rgb)
        if (!std::isfinite(v) || v < 0.0f)
            throw Error("the environment map has negative or non-finite pixels", "light");
    return project_light(
        [&](const glm::vec3& x) { return glm::vec3(sample_equirect(map, glm::dvec3(equirect_direction(x)))); }, order,
        rule);
}

ShLight rotate_light(const ShLight& light, const glm::mat3& rotation) {
    const ShRotation r(light.order, glm::dmat3(rotation));
    std::vector<glm::dvec3> in(light.coeffs.begin(), light.coeffs.end());
    const std::vector<glm::dvec3> out = r.apply(in);
    ShLight l = light;
    for (std::size_t i = 0; i < out.size(); ++i)
        l.coeffs[i] = glm::vec3(out[i]);
    l.sun_direction = glm::normalize(rotation * light.sun_direction);
    return l;
}

glm::vec3 sun_direction(double elevation_deg, double azimuth_deg) {
    const double e = elevation_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
    return glm::vec3(glm::dvec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)));
}

glm::dvec3 sun_transmittance(const SkyModel& model, double altitude_km, double cos_sun_zenith) {
    const Atmosphere& atm = model.atmosphere();
    const double r = atm.planet_radius_km + altitude_km;
    const double c = std::clamp(cos_sun_zenith, -1.0, 1.0);
    if (c < 0.0 && r * r * (1.0 - c * c) < atm.planet_radius_km * atm.planet_radius_km)
        return glm::dvec3(0.0); // behind the planet
    glm::dvec3 tau(0.0);
    for (int k = 0; k < int(atm.components.size()); ++k)
        tau += atm.components[std::size_t(k)].extinction_per_km * model.tables().optical_length(k, altitude_km, c);
    return glm::exp(-tau);
}

SkyProjector::SkyProjector(int order, const SphereRule& rule) : order_(order) {
    check_order(order);
    check_rule(rule);
    const int nc = sh_count(order);
    points_ = rule.points_f32();
    weighted_table_.resize(rule.size() * std::size_t(nc));
    std::vector<double> y(static_cast<std::size_t>(nc));
    for (std::size_t k = 0; k < rule.size(); ++k) {
        sh_eval(order, rule.points[k], y.data());
        for (int i = 0; i < nc; ++i)
            weighted_table_[k * std::size_t(nc) + std::size_t(i)] =
                float(4.0 * M_PI * rule.weights[k] * y[std::size_t(i)]);
    }
}

ShLight SkyProjector::project(const SkySource& sky, const SkyLightSettings& s) const {
    if (!(s.altitude_km >= 0.0) || !std::isfinite(s.altitude_km))
        throw Error(fmt::format("altitude must be ≥ 0 km; got {}", s.altitude_km), "altitude_km");
    if (!(std::abs(s.sun_elevation_deg) <= 90.0))
        throw Error(fmt::format("sun elevation must be -90 to 90 degrees; got {}", s.sun_elevation_deg),
                    "sun_elevation_deg");
    const glm::vec3 sun = sun_direction(s.sun_elevation_deg, s.sun_azimuth_deg);
    const double rho = sky.atmosphere().density_from_altitude(s.altitude_km);
    const float density = float(std::clamp(rho, 1e-30, 1.0));
    std::vector<SkySample> samples(points_.size());
    for (std::size_t k = 0; k < points_.size(); ++k) {
        const glm::vec3 x = points_[k];
        samples[k] = {std::clamp(x.y, -1.0f, 1.0f), std::clamp(glm::dot(x, sun), -1.0f, 1.0f),
                      std::clamp(sun.y, -1.0f, 1.0f), density};
    }
    std::vector<glm::vec3> radiance(points_.size());
    sky.evaluate(samples, radiance);
    const int nc = sh_count(order_);
    if (s.ground_albedo)
        add_lit_ground(sky, s, sun, radiance);
    ShLight l;
    l.order = order_;
    l.coeffs.assign(std::size_t(nc), glm::vec3(0.0f));
    for (std::size_t k = 0; k < points_.size(); ++k) {
        const float* y = &weighted_table_[k * std::size_t(nc)];
        const glm::vec3 f = radiance[k];
        for (int i = 0; i < nc; ++i)
            l.coeffs[std::size_t(i)] += f * y[i];
    }
    l.sun_direction = sun;
    if (s.sun)
        l.sun_irradiance =
            glm::vec3(sky.atmosphere().sun_irradiance * sun_transmittance(sky.tables(), s.altitude_km, double(sun.y)));
    return l;
}

// SkyLightSettings::ground_albedo: the light of a Lambertian ground added to
// the directions that meet it (skybake/prt.h).
void SkyProjector::add_lit_ground(const SkySource& sky, const SkyLightSettings& s, const glm::vec3& sun,
                                  std::vector<glm::vec3>& radiance) const {
    const glm::vec3 albedo = *s.ground_albedo;
    if (!(glm::all(glm::greaterThanEqual(albedo, glm::vec3(0.0f))) && glm::all(glm::lessThanEqual(albedo, glm::vec3(1.0f)))))
        throw Error(fmt::format("the ground albedo must be in [0, 1]; got ({}, {}, {})", albedo.x, albedo.y, albedo.z),
                    "ground_albedo");
    const Atmosphere& atm = sky.atmosphere();
    const SkyModel& tables = sky.tables();
    const int nc = sh_count(order_);
    // The sky's irradiance on a horizontal surface: Σ 4π w_k L_k max(y_k, 0),
    // with 4π w_k = (4π w_k Y_00) / Y_00.
    glm::dvec3 e_sky(0.0);
    for (std::size_t k = 0; k < points_.size(); ++k)
        if (points_[k].y > 0.0f)
            e_sky += glm::dvec3(radiance[k]) * double(weighted_table_[k * std::size_t(nc)]) * (2.0 * std::sqrt(M_PI)) *
                     double(points_[k].y);
    const double R = atm.planet_radius_km, r = R + s.altitude_km;
    const auto tau = [&](double altitude, double cos_zenith) {
        glm::dvec3 t(0.0);
        for (int c = 0; c < int(atm.components.size()); ++c)
            t += atm.components[std::size_t(c)].extinction_per_km * tables.tables().optical_length(c, altitude, cos_zenith);
        return t;
    };
    const glm::dvec3 up(0.0, 1.0, 0.0), sd(sun);
    for (std::size_t k = 0; k < points_.size(); ++k) {
        const glm::dvec3 x(points_[k]);
        const double mu = x.y, disc = r * r * (mu * mu - 1.0) + R * R;
        if (!(mu < 0.0) || disc < 0.0)
            continue; // the ray misses the ground
        const double t = -r * mu - std::sqrt(disc);
        const glm::dvec3 g = r * up + std::max(t, 0.0) * x, up_g = glm::normalize(g);
        const double cos_sun_g = glm::dot(up_g, sd);
        // Back along the ray from the ground: the air between it and the observer.
        const glm::dvec3 seg = t > 0.0 ? glm::exp(-(tau(0.0, glm::dot(up_g, -x)) - tau(s.altitude_km, -mu)))
                                       : glm::dvec3(1.0);
        const glm::dvec3 e = (cos_sun_g > 0.0 ? cos_sun_g * sun_transmittance(tables, 0.0, cos_sun_g) : glm::dvec3(0.0)) +
                             e_sky;
        radiance[k] += glm::vec3(seg * glm::dvec3(albedo) * (1.0 / M_PI) * e);
    }
}

ShLight sky_light(const SkySource& sky, const SkyLightSettings& settings, int order, const SphereRule& rule) {
    return SkyProjector(order, rule).project(sky, settings);
}

} // namespace skybake
