// Sky images from an observer at any altitude: fisheye, panorama and pinhole
// views of the sky, the ground and the planet (Pietras & Rudnicki, seed 000,
// section VII views). Per-pixel work is in render_hd.h.
#include <cmath>

#include "core/parallel.h"
#include "core/progress.h"
#include "skybake/error.h"
#include "sky/internal.h"
#include "sky/render_hd.h"

namespace skybake {

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Exact counterpart of sky::shade_ray, in double (slow; for checks).
glm::dvec3 shade_ray_exact(const Atmosphere& atm, const sky::RenderHD& p, const glm::dvec3& d, double tol) {
    const glm::dvec3 eye(0.0, 0.0, double(atm.planet_radius_km) + double(p.eye_h));
    const glm::dvec3 sun = glm::normalize(glm::dvec3(p.sun));
    double enter, exit;
    bool ground;
    glm::dvec3 c(0.0);
    if (!sky::atmosphere_segment(atm, eye, d, enter, exit, ground)) {
        if (p.sun_disc_radiance > 0.0f && glm::dot(d, sun) >= double(p.sun_cos_radius))
            c += glm::dvec3(p.sun_disc_radiance);
        return c * glm::dvec3(p.irradiance);
    }
    glm::dvec3 t;
    c = sky::inscatter_exact(atm, eye + enter * d, d, exit - enter, sun, tol, &t);
    const bool multiple = p.atm.ms.method != sky::kMultipleNone;
    if (multiple) // the tables' multiple scattering on top of the exact single scattering
        c += glm::dvec3(sky::multiple_residual(
            p.atm, sky::ObserverHD{p.eye_r, p.eye_h, float(d.z), float(glm::dot(d, sun)), float(sun.z)}, p.steps, p.spacing));
    if (ground) {
        const glm::dvec3 g = eye + exit * d;
        const double cos_sun = glm::dot(glm::normalize(g), sun);
        if (cos_sun > 0.0 || multiple) {
            glm::dvec3 r(0.0);
            if (cos_sun > 0.0)
                r = glm::dvec3(p.albedo) * (cos_sun / 3.14159265358979323846) * sky::sun_transmittance_exact(atm, g, sun) * t;
            if (multiple)
                r += glm::dvec3(p.albedo) / 3.14159265358979323846 *
                     glm::dvec3(sky::sky_irradiance_lookup(p.atm.ms, p.atm.R0, p.atm.Rtop, 0.0f, float(cos_sun))) * t;
            if (p.published_ground) {
                glm::dvec3 b(0.0);
                for (const AtmosphereComponent& k : atm.components)
                    b += k.scattering_per_km * relative_density(k, 0.0);
                r *= b;
            }
            c += r;
        }
    } else if (p.sun_disc_radiance > 0.0f && glm::dot(d, sun) >= double(p.sun_cos_radius)) {
        c += sky::sun_transmittance_exact(atm, eye + enter * d, d) * double(p.sun_disc_radiance);
    }
    return c * glm::dvec3(p.irradiance);
}

} // namespace

namespace sky {

void set_scene_hd(RenderHD& p, const SkyModel& model, bool published_ground, bool sun_disc) {
    const Atmosphere& atm = model.atmosphere();
    p.steps = model.options().steps;
    p.spacing = model.options().uniform_steps ? kStepsUniform : kStepsGraded;
    p.albedo = glm::vec3(atm.ground_albedo);
    p.published_ground = published_ground ? 1 : 0;
    p.irradiance = glm::vec3(atm.sun_irradiance);
    p.sun_cos_radius = float(std::cos(atm.sun_angular_radius_rad));
    p.sun_disc_radiance =
        sun_disc ? float(1.0 / (3.14159265358979323846 * atm.sun_angular_radius_rad * atm.sun_angular_radius_rad))
                 : 0.0f;
}

RenderHD make_render_hd(const SkyModel& model, const SkyRenderSettings& s) {
    const Atmosphere& atm = model.atmosphere();
    if (!(std::isfinite(s.altitude_km) && s.altitude_km >= 0.0 && s.altitude_km < 1e7))
        throw Error("the observer altitude must be 0 to 1e7 km", "altitude_km");
    if (!(std::isfinite(s.sun_elevation_deg) && std::abs(s.sun_elevation_deg) <= 90.0))
        throw Error("the sun elevation must be in [-90, 90] degrees", "sun_elevation_deg");
    if (!std::isfinite(s.sun_azimuth_deg))
        throw Error("the sun azimuth must be a finite number of degrees", "sun_azimuth_deg");
    if (s.view == SkyView::Camera && !(s.fov_deg > 0.0 && s.fov_deg < 180.0))
        throw Error("the field of view must be in (0, 180) degrees", "fov_deg");
    if (!(std::isfinite(s.yaw_deg) && std::isfinite(s.pitch_deg) && std::abs(s.pitch_deg) <= 90.0))
        throw Error("yaw must be finite and pitch in [-90, 90] degrees", "yaw_deg/pitch_deg");
    if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
        throw Error("image size must be 1 to 16384 pixels on each side", "width/height");

    sky::RenderHD p;
    p.atm = sky::atmosphere_hd(model);
    p.eye_h = float(s.altitude_km);
    p.eye_r = float(atm.planet_radius_km + s.altitude_km);
    p.sun = sky::direction_from_angles(float(s.sun_azimuth_deg * kDeg), float(s.sun_elevation_deg * kDeg));
    p.view = int(s.view);
    p.forward = sky::direction_from_angles(float(s.yaw_deg * kDeg), float(s.pitch_deg * kDeg));
    glm::vec3 right = glm::cross(p.forward, glm::vec3(0.0f, 0.0f, 1.0f));
    if (glm::length(right) < 1e-6f) // looking straight up or down: keep yaw's sideways direction
        right = glm::vec3(std::sin(float(s.yaw_deg * kDeg)), -std::cos(float(s.yaw_deg * kDeg)), 0.0f);
    p.right = glm::normalize(right);
    p.up = glm::cross(p.right, p.forward);
    p.tan_half_fov = float(std::tan(0.5 * s.fov_deg * kDeg));
    p.width = s.width;
    p.height = s.height;
    sky::set_scene_hd(p, model, s.published_ground, s.sun_disc);
    return p;
}

} // namespace sky

Image render_sky(const SkyModel& model, const SkyRenderSettings& s) {
    const Atmosphere& atm = model.atmosphere();
    const sky::RenderHD p = sky::make_render_hd(model, s);

    const bool exact = s.method == SkyMethod::Exact;
    const double tol = model.options().exact_tolerance;
    return sky::render_pixels(p, [&](const glm::vec3& d) {
        return exact ? glm::vec3(shade_ray_exact(atm, p, glm::normalize(glm::dvec3(d)), tol)) : sky::shade_ray(p, d);
    });
}

} // namespace skybake
