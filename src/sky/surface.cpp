// Colour of the surface seen through the atmosphere: Pietras & Rudnicki
// (seed 000), section IV.
//
// In-scattering between an observer I and a surface point II: the seed takes
// the difference I(I) − I(probe at II looking the same way); exactly, it is
// the single-scattering integral over the segment I–II. Since
// I(I) = inscatter(I→II) + T(I→II)·I(II), the seed's difference misses
// (1 − T)·I(II): nothing for points on the ground (the probe's ray ends at
// once), more for raised points.
//
// Reflected light: the seed prints I = b C F ρ_II exp(−b(L[ρ_I, cos α_I] −
// L[ρ_II, cos α_II] + L[ρ_II, cos θ_II])). For a surface the factor b ρ_II
// (a volume's scattering) has no place: a Lambertian surface with albedo C
// lit by unit irradiance has radiance C cos θ_II / π. We keep the seed's
// attenuation term and use that radiance.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "sky/internal.h"

namespace skybake {

SurfaceLight surface_light(const SkyModel& model, const glm::dvec3& observer, const glm::dvec3& surface,
                           const glm::dvec3& sun_in, const glm::dvec3& albedo) {
    const Atmosphere& atm = model.atmosphere();
    const sky::AtmosphereHD& hd = sky::atmosphere_hd(model);
    const glm::dvec3 sun = glm::normalize(sun_in);
    SurfaceLight out;
    const glm::dvec3 delta = surface - observer;
    const double length = glm::length(delta);
    assert(length > 0.0);
    const glm::dvec3 V = delta / length;
    const double rs = glm::length(surface);
    const glm::dvec3 n = surface / rs;
    const double hs = rs - atm.planet_radius_km;
    assert(hs > -1e-6);

    // Exact: the part of the segment inside the atmosphere.
    double enter = 0.0, exit = 0.0;
    bool ground = false;
    glm::dvec3 t_exact(1.0);
    if (sky::atmosphere_segment(atm, observer, V, enter, exit, ground) && enter < length)
        out.inscatter_exact = sky::inscatter_exact(atm, observer + enter * V, V, std::min(length, exit) - enter, sun,
                                                   model.options().exact_tolerance, &t_exact);
    out.transmittance_exact = t_exact;
    const double cos_sun = glm::dot(n, sun);
    const glm::dvec3 lambert = albedo * (std::max(0.0, cos_sun) / 3.14159265358979323846);
    out.reflected_exact = lambert * sky::sun_transmittance_exact(atm, surface, sun) * t_exact;
    // With multiple scattering the surface is also lit by the sky.
    const glm::dvec3 sky_light = albedo / 3.14159265358979323846 * model.sky_irradiance(hs, cos_sun);
    out.reflected_exact += sky_light * t_exact;

    // The seed's difference of two sky evaluations.
    const double ro = glm::length(observer);
    const double mu_vs = glm::dot(V, sun);
    const glm::dvec3 i_obs = model.radiance_at_radius(ro, glm::dot(observer, V) / ro, mu_vs,
                                                      glm::dot(observer, sun) / ro, SkyMethod::Tables);
    const glm::dvec3 i_probe =
        model.radiance_at_radius(rs, glm::dot(n, V), mu_vs, cos_sun, SkyMethod::Tables);
    out.inscatter_seed = i_obs - i_probe;

    // Reflected light with the tables.
    if (cos_sun > 0.0 || hd.ms.irradiance != nullptr) {
        sky::ObserverHD e = sky::make_observer(atm, ro, glm::dot(observer, V) / ro, mu_vs, glm::dot(observer, sun) / ro);
        glm::vec3 t(1.0f);
        if (sky::enter_atmosphere(hd, e))
            t = sky::segment_transmittance(hd, e.r, e.h, e.cv, float(rs), float(hs), float(glm::dot(n, V)));
        if (cos_sun > 0.0)
            out.reflected_tables =
                lambert * glm::dvec3(sky::sun_transmittance(hd, float(rs), float(hs), float(cos_sun))) * glm::dvec3(t);
        out.reflected_tables += sky_light * glm::dvec3(t);
    }
    return out;
}

} // namespace skybake
