// The per-ray shading of a neural sky image, shared by the CPU and CUDA
// renderers: sky::shade_ray (src/sky/render_hd.h) with the marching sum
// replaced by the network (seed 000, sections III and IV).
#pragma once

#include "neural/mlp_hd.h"
#include "sky/render_hd.h"

namespace skybake::neural {

// sky::shade_ray with the marching sum replaced by an approximation of the sky
// function: sky(cos α0, cos β0, cos θ0, ρ0) -> radiance (the network, or the
// look-up table it is compared with).
template <class SkyFunction>
SKYBAKE_HD_INLINE glm::vec3 shade_ray_approximate(const sky::RenderHD& p, const SkyFunction& neural_sky,
                                                  const glm::vec3& d) {
    const sky::AtmosphereHD& a = p.atm;
    sky::ObserverHD o{p.eye_r, p.eye_h, d.z, glm::dot(d, p.sun), p.sun.z};
    sky::ObserverHD e = o;
    const bool inside = sky::enter_atmosphere(a, e); // the ray's first point in the atmosphere
    glm::vec3 c(0.0f);
    if (inside) {
        const float rho = sky::component_density(a.comp[0], e.h);
        c = neural_sky(e.cv, e.cvs, e.cs, rho);
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
            c = glm::max(c - neural_sky(glm::dot(n, d), o.cvs, cos_sun, 1.0f), glm::vec3(0.0f));
        if (cos_sun > 0.0f) {
            glm::vec3 reflected = p.albedo * (cos_sun / sky::kPi) * sky::sun_transmittance(a, a.R0, 0.0f, cos_sun);
            if (p.published_ground) {
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

// The network's sky.
struct NetworkSky {
    const MlpHD& net;
    SKYBAKE_HD_INLINE glm::vec3 operator()(float cv, float cvs, float cs, float rho) const {
        return neural_sky(net, cv, cvs, cs, rho);
    }
};

SKYBAKE_HD_INLINE glm::vec3 shade_ray_neural(const sky::RenderHD& p, const MlpHD& net, const glm::vec3& d) {
    return shade_ray_approximate(p, NetworkSky{net}, d);
}

} // namespace skybake::neural
