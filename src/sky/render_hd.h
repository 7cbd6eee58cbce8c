// Per-pixel camera and planet ray setup for sky images, shared by the CPU
// renderer and a CUDA one. The observer stands above the planet's "north
// pole": a local frame with z up, azimuth measured from +x towards +y.
//
// Pietras & Rudnicki (seed 000) sections II and IV: the sky is the marching
// sum; the ground adds the sunlight reflected by a Lambertian surface,
// attenuated by the atmosphere on both paths (and, with multiple scattering,
// the reflected sky irradiance).
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "sky/sky_hd.h"

namespace skybake::sky {

enum : int { kViewFisheye = 0, kViewPanorama = 1, kViewCamera = 2 };

struct RenderHD {
    AtmosphereHD atm;
    float eye_r = 6360.0f; // observer radius, km
    float eye_h = 0.0f;    // observer altitude, km
    glm::vec3 sun{0.0f, 0.0f, 1.0f};
    int view = kViewFisheye;
    glm::vec3 forward{1.0f, 0.0f, 0.0f}, right{0.0f, -1.0f, 0.0f}, up{0.0f, 0.0f, 1.0f}; // camera basis
    float tan_half_fov = 1.0f;
    int width = 1, height = 1;
    int steps = 16;
    int spacing = kStepsGraded;
    glm::vec3 albedo{0.1f};
    int published_ground = 0; // 1: the seed's printed surface term, scaled by Σ b_k ρ_k (see surface.cpp)
    glm::vec3 irradiance{1.0f};
    float sun_cos_radius = 1.0f; // cos of the sun's angular radius
    float sun_disc_radiance = 0.0f; // 1/(π θ²) per unit irradiance; 0 hides the disc
};

// Direction of unit length in the local frame, from azimuth and elevation (radians).
SKYBAKE_HD_INLINE glm::vec3 direction_from_angles(float azimuth, float elevation) {
    return glm::vec3(cosf(elevation) * cosf(azimuth), cosf(elevation) * sinf(azimuth), sinf(elevation));
}

// View direction through the centre of pixel (x, y); false outside the fisheye circle.
SKYBAKE_HD_INLINE bool pixel_direction(const RenderHD& p, int x, int y, glm::vec3& dir) {
    const float fx = (float(x) + 0.5f) / float(p.width);
    const float fy = (float(y) + 0.5f) / float(p.height);
    if (p.view == kViewPanorama) {
        dir = direction_from_angles(2.0f * kPi * fx, 0.5f * kPi - kPi * fy);
        return true;
    }
    if (p.view == kViewFisheye) {
        const float side = float(p.width < p.height ? p.width : p.height);
        const float nx = (2.0f * (float(x) + 0.5f) - float(p.width)) / side;
        const float ny = (float(p.height) - 2.0f * (float(y) + 0.5f)) / side;
        const float rr = sqrtf(nx * nx + ny * ny);
        if (rr > 1.0f)
            return false;
        const float zenith = 0.5f * kPi * rr;
        const float az = atan2f(nx, ny);
        dir = direction_from_angles(az, 0.5f * kPi - zenith);
        return true;
    }
    const float px = (2.0f * fx - 1.0f) * p.tan_half_fov;
    const float py = (1.0f - 2.0f * fy) * p.tan_half_fov * float(p.height) / float(p.width);
    dir = glm::normalize(p.forward + px * p.right + py * p.up);
    return true;
}

// Radiance along one view ray from the observer (per pixel, times irradiance).
SKYBAKE_HD_INLINE glm::vec3 shade_ray(const RenderHD& p, const glm::vec3& d) {
    const AtmosphereHD& a = p.atm;
    ObserverHD o{p.eye_r, p.eye_h, d.z, glm::dot(d, p.sun), p.sun.z};
    glm::vec3 c = sky_sum(a, o, p.steps, p.spacing);

    // Ground: first intersection with the sphere R0.
    const float b = p.eye_r * d.z;
    const float disc = b * b - p.eye_h * (2.0f * a.R0 + p.eye_h);
    const bool ground = b < 0.0f && disc >= 0.0f;
    ObserverHD e = o;
    const bool inside = enter_atmosphere(a, e); // the ray's first point in the atmosphere
    if (ground) {
        const float t = -b - sqrtf(disc);
        const glm::vec3 g(t * d.x, t * d.y, p.eye_r + t * d.z);
        const glm::vec3 n = g / glm::length(g);
        const float cos_sun = glm::dot(n, p.sun);
        if (cos_sun > 0.0f || a.ms.irradiance != nullptr) {
            glm::vec3 reflected(0.0f);
            if (cos_sun > 0.0f)
                reflected = p.albedo * (cos_sun / kPi) * sun_transmittance(a, a.R0, 0.0f, cos_sun);
            if (a.ms.irradiance != nullptr) // the sky's light, with multiple scattering
                reflected += p.albedo * (1.0f / kPi) * sky_irradiance_lookup(a.ms, a.R0, a.Rtop, 0.0f, cos_sun);
            if (p.published_ground) {
                glm::vec3 b(0.0f);
                for (int k = 0; k < a.count; ++k)
                    b += a.comp[k].sca * component_density(a.comp[k], 0.0f);
                reflected *= b;
            }
            if (inside)
                reflected *= segment_transmittance(a, e.r, e.h, e.cv, a.R0, 0.0f, glm::dot(n, d));
            c += reflected;
        }
    } else if (p.sun_disc_radiance > 0.0f && glm::dot(d, p.sun) >= p.sun_cos_radius) {
        glm::vec3 t(1.0f);
        if (inside)
            t = sun_transmittance(a, e.r, e.h, e.cv);
        c += t * p.sun_disc_radiance;
    }
    return c * p.irradiance;
}

} // namespace skybake::sky
