// Sky images with the neural sky: Pietras & Rudnicki (seed 000), section III
// for the sky and the light scattered in front of the ground (one network
// evaluation per view ray, at the point where the ray enters the atmosphere),
// section IV for the ground: the in-scattered light in front of it is the
// difference of two network evaluations (observer and a probe at the surface
// point), the reflected light and the sun disc come from the optical-length
// tables. The camera, the planet and the ground are those
// of the sky module's renderer (src/sky/render_hd.h).
#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "core/progress.h"
#include "neural/internal.h"
#include "sky/render_hd.h"
#include "skybake/error.h"

namespace skybake {

using namespace neural;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// sky::shade_ray with the marching sum replaced by the network.
glm::vec3 shade_ray_neural(const sky::RenderHD& p, const MlpHD& net, const glm::vec3& d) {
    const sky::AtmosphereHD& a = p.atm;
    sky::ObserverHD o{p.eye_r, p.eye_h, d.z, glm::dot(d, p.sun), p.sun.z};
    sky::ObserverHD e = o;
    const bool inside = sky::enter_atmosphere(a, e); // the ray's first point in the atmosphere
    glm::vec3 c(0.0f);
    if (inside) {
        const float rho = sky::component_density(a.comp[0], e.h);
        c = neural_sky(net, e.cv, e.cvs, e.cs, rho);
    }
    const float b = p.eye_r * d.z;
    const float disc = b * b - p.eye_h * (2.0f * a.R0 + p.eye_h);
    const bool ground = b < 0.0f && disc >= 0.0f;
    if (ground) {
        const float t = -b - sqrtf(disc);
        const glm::vec3 g(t * d.x, t * d.y, p.eye_r + t * d.z);
        const glm::vec3 n = g / glm::length(g);
        const float cos_sun = glm::dot(n, p.sun);
        // Seed section IV: the light scattered between the observer and the
        // surface is N(observer) − N(probe at the surface point, looking the
        // same way). The probe's true value is 0 (its ray ends at once); the
        // network's value there is its smoothing error across the horizon,
        // which the difference removes.
        if (inside)
            c = glm::max(c - neural_sky(net, glm::dot(n, d), o.cvs, cos_sun, 1.0f), glm::vec3(0.0f));
        if (cos_sun > 0.0f) {
            glm::vec3 reflected = p.albedo * (cos_sun / sky::kPi) * sky::sun_transmittance(a, a.R0, 0.0f, cos_sun);
            if (p.seed_ground) {
                glm::vec3 bs(0.0f);
                for (int k = 0; k < a.count; ++k)
                    bs += a.comp[k].sca * sky::component_density(a.comp[k], 0.0f);
                reflected *= bs;
            }
            if (inside)
                reflected *= sky::segment_transmittance(a, e.r, e.h, e.cv, a.R0, 0.0f, glm::dot(n, d));
            c += reflected;
        }
    } else if (p.sun_disc_radiance > 0.0f && glm::dot(d, p.sun) >= p.sun_cos_radius) {
        glm::vec3 t(1.0f);
        if (inside)
            t = sky::sun_transmittance(a, e.r, e.h, e.cv);
        c += t * p.sun_disc_radiance;
    }
    return c * p.irradiance;
}

} // namespace

Image render_neural_sky(const NeuralSky& net, const SkyModel& model, const SkyRenderSettings& s) {
    net.validate("neural sky");
    const Atmosphere& atm = model.atmosphere();
    if (!(std::isfinite(s.altitude_km) && s.altitude_km >= 0.0 && s.altitude_km < 1e7))
        throw Error("the observer altitude must be 0 to 1e7 km", "--altitude-km");
    if (!(std::isfinite(s.sun_elevation_deg) && std::abs(s.sun_elevation_deg) <= 90.0))
        throw Error("the sun elevation must be in [-90, 90] degrees", "--sun-elevation-deg");
    if (!std::isfinite(s.sun_azimuth_deg))
        throw Error("the sun azimuth must be a finite number of degrees", "--sun-azimuth-deg");
    if (s.view == SkyView::Camera && !(s.fov_deg > 0.0 && s.fov_deg < 180.0))
        throw Error("the field of view must be in (0, 180) degrees", "--fov");
    if (!(std::isfinite(s.yaw_deg) && std::isfinite(s.pitch_deg) && std::abs(s.pitch_deg) <= 90.0))
        throw Error("yaw must be finite and pitch in [-90, 90] degrees", "--yaw/--pitch");
    if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
        throw Error("image size must be 1 to 16384 pixels on each side", "--size");

    sky::RenderHD p;
    p.atm = *static_cast<const sky::AtmosphereHD*>(model.device_view());
    p.eye_h = float(s.altitude_km);
    p.eye_r = float(atm.planet_radius_km + s.altitude_km);
    p.sun = sky::direction_from_angles(float(s.sun_azimuth_deg * kDeg), float(s.sun_elevation_deg * kDeg));
    p.view = int(s.view);
    p.forward = sky::direction_from_angles(float(s.yaw_deg * kDeg), float(s.pitch_deg * kDeg));
    glm::vec3 right = glm::cross(p.forward, glm::vec3(0.0f, 0.0f, 1.0f));
    if (glm::length(right) < 1e-6f)
        right = glm::vec3(std::sin(float(s.yaw_deg * kDeg)), -std::cos(float(s.yaw_deg * kDeg)), 0.0f);
    p.right = glm::normalize(right);
    p.up = glm::cross(p.right, p.forward);
    p.tan_half_fov = float(std::tan(0.5 * s.fov_deg * kDeg));
    p.width = s.width;
    p.height = s.height;
    p.albedo = glm::vec3(atm.ground_albedo);
    p.seed_ground = s.seed_ground ? 1 : 0;
    p.irradiance = glm::vec3(atm.sun_irradiance);
    p.sun_cos_radius = float(std::cos(atm.sun_angular_radius_rad));
    p.sun_disc_radiance =
        s.sun_disc ? float(1.0 / (3.14159265358979323846 * atm.sun_angular_radius_rad * atm.sun_angular_radius_rad))
                   : 0.0f;
    const MlpHD hd = make_mlp_hd(net);

    Image image(s.width, s.height);
    Progress progress("render", std::uint64_t(s.height));
    parallel_for(std::size_t(s.height), 1, [&](std::size_t y0, std::size_t y1) {
        for (std::size_t y = y0; y < y1; ++y) {
            for (int x = 0; x < s.width; ++x) {
                glm::vec3 d;
                if (!sky::pixel_direction(p, x, int(y), d))
                    continue;
                const glm::vec3 c = shade_ray_neural(p, hd, d);
                float* px = image.pixel(x, int(y));
                px[0] = c.x;
                px[1] = c.y;
                px[2] = c.z;
            }
            progress.advance();
        }
    });
    progress.finish();
    return image;
}

std::vector<SeedView> seed_views(int width, int height) {
    auto view = [&](const char* name, double alt, double sun_el, double sun_az, double pitch, double yaw) {
        SeedView v;
        v.name = name;
        v.settings.altitude_km = alt;
        v.settings.sun_elevation_deg = sun_el;
        v.settings.sun_azimuth_deg = sun_az;
        v.settings.view = SkyView::Camera;
        v.settings.fov_deg = 90.0;
        v.settings.pitch_deg = pitch;
        v.settings.yaw_deg = yaw;
        v.settings.width = width;
        v.settings.height = height;
        return v;
    };
    return {view("1_sea_level", 0.0, 35.0, 40.0, 15.0, 0.0),   view("2_higher", 5.0, 35.0, 40.0, 5.0, 0.0),
            view("3_higher", 30.0, 35.0, 40.0, -10.0, 0.0),    view("4_higher", 120.0, 35.0, 40.0, -25.0, 0.0),
            view("5_low_sun", 0.0, 2.0, 0.0, 10.0, 0.0),       view("6_very_high", 1500.0, 35.0, 40.0, -70.0, 0.0)};
}

double auto_exposure_ev(const Image& img) {
    std::vector<float> lum;
    lum.reserve(img.rgb.size() / 3);
    for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3) {
        const float l = 0.2126f * img.rgb[i] + 0.7152f * img.rgb[i + 1] + 0.0722f * img.rgb[i + 2];
        if (l > 0.0f && std::isfinite(l))
            lum.push_back(l);
    }
    if (lum.empty())
        return 0.0;
    const std::size_t k = std::min(lum.size() - 1, std::size_t(double(lum.size()) * 0.98));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    return -std::log2(double(lum[k]));
}

double image_psnr_db(const Image& a, const Image& b, const ToneMap& tm) {
    if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
        throw Error("images of different sizes", "PSNR");
    double se = 0.0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        const double x = linear_to_srgb(tone_map_value(a.rgb[i], tm));
        const double y = linear_to_srgb(tone_map_value(b.rgb[i], tm));
        se += (x - y) * (x - y);
    }
    const double mse = se / double(std::max<std::size_t>(1, a.rgb.size()));
    return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : 999.0;
}

} // namespace skybake
