// Per-ray shading of sky images, written once in the common subset of C++ and
// GLSL (core/shared_source.h): the CPU and CUDA renderers include it through
// sky/render_hd.h, and the planet renderer's shaders embed its text after
// sky_shared.h. The observer stands at radius eye_r with local vertical
// `zenith`; the CPU and CUDA images put it above the planet's "north pole"
// (zenith +z, azimuth measured from +x towards +y).
//
// Pietras & Rudnicki (seed 000) sections II, III and IV: the sky is the
// marching sum, or the network in its place; the ground adds the sunlight
// reflected by a Lambertian surface, attenuated by the atmosphere on both
// paths (and, with multiple scattering, the reflected sky irradiance).
//
// Besides sky_shared.h's definitions, each language defines the sky function
// that replaces the sum in the *_approximate shading (the network, or the
// look-up table it is compared with): SB_SKY_TEMPLATE before such a function,
// SB_SKY_PARAM among its parameters, SB_SKY(cv, cvs, cs, rho) to call it (C++:
// a functor argument; GLSL: skybake_sky(), which the network's export defines).
#ifndef SKYBAKE_SKY_SHADE_SHARED_H
#define SKYBAKE_SKY_SHADE_SHARED_H

const int kViewFisheye = 0;
const int kViewPanorama = 1;
const int kViewCamera = 2;

struct RenderHD {
    AtmosphereHD atm;
    float eye_r SB_INIT(6360.0f);                  // observer radius, km
    float eye_h SB_INIT(0.0f);                     // observer altitude, km
    vec3 zenith SB_INIT(vec3(0.0f, 0.0f, 1.0f));   // unit local vertical at the observer
    vec3 sun SB_INIT(vec3(0.0f, 0.0f, 1.0f));      // unit direction to the sun
    int view SB_INIT(kViewFisheye);
    vec3 forward SB_INIT(vec3(1.0f, 0.0f, 0.0f));  // camera basis
    vec3 right SB_INIT(vec3(0.0f, -1.0f, 0.0f));
    vec3 up SB_INIT(vec3(0.0f, 0.0f, 1.0f));
    float tan_half_fov SB_INIT(1.0f);
    int width SB_INIT(1);
    int height SB_INIT(1);
    int steps SB_INIT(16);
    int spacing SB_INIT(kStepsGraded);
    vec3 albedo SB_INIT(vec3(0.1f));
    int published_ground SB_INIT(0); // 1: the seed's printed surface term, scaled by Σ b_k ρ_k (see surface.cpp)
    vec3 irradiance SB_INIT(vec3(1.0f));
    float sun_cos_radius SB_INIT(1.0f);    // cos of the sun's angular radius
    float sun_disc_radiance SB_INIT(0.0f); // 1/(π θ²) per unit irradiance; 0 hides the disc
};

// Direction of unit length in the local frame, from azimuth and elevation (radians).
SKYBAKE_HD_INLINE vec3 direction_from_angles(float azimuth, float elevation) {
    return vec3(cosf(elevation) * cosf(azimuth), cosf(elevation) * sinf(azimuth), sinf(elevation));
}

// View direction through the centre of pixel (x, y); false outside the fisheye circle.
SKYBAKE_HD_INLINE bool pixel_direction(SB_IN(RenderHD) p, int x, int y, SB_OUT(vec3) dir) {
    float fx = (float(x) + 0.5f) / float(p.width);
    float fy = (float(y) + 0.5f) / float(p.height);
    dir = vec3(0.0f);
    if (p.view == kViewPanorama) {
        dir = direction_from_angles(2.0f * kPi * fx, 0.5f * kPi - kPi * fy);
        return true;
    }
    if (p.view == kViewFisheye) {
        float side = float(p.width < p.height ? p.width : p.height);
        float nx = (2.0f * (float(x) + 0.5f) - float(p.width)) / side;
        float ny = (float(p.height) - 2.0f * (float(y) + 0.5f)) / side;
        float rr = sqrtf(nx * nx + ny * ny);
        if (rr > 1.0f)
            return false;
        float zenith = 0.5f * kPi * rr;
        float az = atan2f(nx, ny);
        dir = direction_from_angles(az, 0.5f * kPi - zenith);
        return true;
    }
    float px = (2.0f * fx - 1.0f) * p.tan_half_fov;
    float py = (1.0f - 2.0f * fy) * p.tan_half_fov * float(p.height) / float(p.width);
    dir = normalize(p.forward + px * p.right + py * p.up);
    return true;
}

SKYBAKE_HD_INLINE ObserverHD view_observer(SB_IN(RenderHD) p, vec3 d) {
    return observer_hd(p.eye_r, p.eye_h, dot(d, p.zenith), dot(d, p.sun), dot(p.zenith, p.sun));
}

// The light a Lambertian surface point sends to the observer along the view
// direction d: the sun's and (with multiple scattering) the sky's light,
// reflected, then attenuated on the way to the observer. up_g is the point's
// local vertical, nrm its shading normal, r_g and h_g its radius and altitude;
// e is the observer moved to where the view ray enters the atmosphere
// (inside: it does).
SKYBAKE_HD_INLINE vec3 surface_light(SB_IN(RenderHD) p, SB_IN(ObserverHD) e, bool inside, vec3 d, vec3 up_g, vec3 nrm,
                                     float r_g, float h_g) {
    float cos_sun = dot(nrm, p.sun);
    float cos_sun_g = dot(up_g, p.sun);
    vec3 reflected = vec3(0.0f);
    if (!(cos_sun > 0.0f || p.atm.ms.irr_nr > 0))
        return reflected;
    if (cos_sun > 0.0f)
        reflected = p.albedo * (cos_sun / kPi) * sun_transmittance(p.atm, r_g, h_g, cos_sun_g);
    if (p.atm.ms.irr_nr > 0) // the sky's light, with multiple scattering
        reflected += p.albedo * (1.0f / kPi) * sky_irradiance_lookup(p.atm.ms, p.atm.R0, p.atm.Rtop, h_g, cos_sun_g);
    if (p.published_ground != 0) {
        vec3 bs = vec3(0.0f);
        for (int k = 0; k < p.atm.count; ++k)
            bs += p.atm.comp[k].sca * component_density(p.atm.comp[k], h_g);
        reflected *= bs;
    }
    if (inside)
        reflected *= segment_transmittance(p.atm, e.r, e.h, e.cv, r_g, h_g, dot(up_g, d));
    return reflected;
}

// Where the view ray d meets the smooth ground (the sphere R0): false when it
// does not; else n is the unit vertical there.
SKYBAKE_HD_INLINE bool ground_hit(SB_IN(RenderHD) p, SB_IN(ObserverHD) o, vec3 d, SB_OUT(vec3) n) {
    float b = p.eye_r * o.cv;
    float disc = b * b - p.eye_h * (2.0f * p.atm.R0 + p.eye_h);
    n = p.zenith;
    if (!(b < 0.0f && disc >= 0.0f))
        return false;
    float t = -b - sqrtf(disc);
    vec3 g = p.eye_r * p.zenith + t * d;
    n = g / length(g);
    return true;
}

// Everything but the sun disc along the unit view direction d, per unit
// irradiance: the sky, or the light in front of the ground and the lit ground.
// want_sun: sun_t is the transmittance towards the sun disc (0 where the ray
// meets the ground); else sun_t is 0.
SKYBAKE_HD_INLINE vec3 shade_sky(SB_IN(RenderHD) p, vec3 d, bool want_sun, SB_OUT(vec3) sun_t) {
    ObserverHD o = view_observer(p, d);
    vec3 c = sky_sum(p.atm, o, p.steps, p.spacing);
    ObserverHD e = o;
    bool inside = enter_atmosphere(p.atm, e); // the ray's first point in the atmosphere
    vec3 n;
    sun_t = vec3(0.0f);
    if (ground_hit(p, o, d, n))
        c += surface_light(p, e, inside, d, n, n, p.atm.R0, 0.0f);
    else if (want_sun)
        sun_t = inside ? sun_transmittance(p.atm, e.r, e.h, e.cv) : vec3(1.0f);
    return c;
}

// shade_sky with the marching sum replaced by the sky function.
SB_SKY_TEMPLATE
SKYBAKE_HD_INLINE vec3 shade_sky_approximate(SB_IN(RenderHD) p, SB_SKY_PARAM, vec3 d, bool want_sun,
                                             SB_OUT(vec3) sun_t) {
    ObserverHD o = view_observer(p, d);
    ObserverHD e = o;
    bool inside = enter_atmosphere(p.atm, e);
    vec3 c = vec3(0.0f);
    if (inside)
        c = SB_SKY(e.cv, e.cvs, e.cs, component_density(p.atm.comp[0], e.h));
    vec3 n;
    sun_t = vec3(0.0f);
    if (ground_hit(p, o, d, n)) {
        // Seed section IV: the light scattered between the observer and the
        // surface is N(observer) − N(probe at the surface point, looking the
        // same way). The probe's true value is 0 (its ray ends at once); the
        // network's value there is its smoothing error across the horizon,
        // which the difference removes.
        if (inside)
            c = max(c - SB_SKY(dot(n, d), o.cvs, dot(n, p.sun), 1.0f), vec3(0.0f));
        c += surface_light(p, e, inside, d, n, n, p.atm.R0, 0.0f);
    } else if (want_sun) {
        sun_t = inside ? sun_transmittance(p.atm, e.r, e.h, e.cv) : vec3(1.0f);
    }
    return c;
}

// Whether d sees the sun disc.
SKYBAKE_HD_INLINE bool sees_sun_disc(SB_IN(RenderHD) p, vec3 d) {
    return p.sun_disc_radiance > 0.0f && dot(d, p.sun) >= p.sun_cos_radius;
}

// Radiance along one view ray from the observer (per pixel, times irradiance).
SKYBAKE_HD_INLINE vec3 shade_ray(SB_IN(RenderHD) p, vec3 d) {
    bool disc = sees_sun_disc(p, d);
    vec3 sun_t;
    vec3 c = shade_sky(p, d, disc, sun_t);
    if (disc)
        c += sun_t * p.sun_disc_radiance;
    return c * p.irradiance;
}

SB_SKY_TEMPLATE
SKYBAKE_HD_INLINE vec3 shade_ray_approximate(SB_IN(RenderHD) p, SB_SKY_PARAM, vec3 d) {
    bool disc = sees_sun_disc(p, d);
    vec3 sun_t;
    vec3 c = shade_sky_approximate(p, SB_SKY_ARG, d, disc, sun_t);
    if (disc)
        c += sun_t * p.sun_disc_radiance;
    return c * p.irradiance;
}

// The ground seen along d at the surface point g (planet-centred, km) with
// unit shading normal nrm and altitude h_g (0 on the smooth sphere), at
// distance dist from the observer: the planet renderer's terrain.
SKYBAKE_HD_INLINE vec3 shade_surface(SB_IN(RenderHD) p, vec3 d, vec3 g, vec3 nrm, float h_g, float dist) {
    ObserverHD o = view_observer(p, d);
    ObserverHD e = o;
    bool inside = enter_atmosphere(p.atm, e);
    vec3 up_g = g / length(g);
    vec3 c = sky_sum_to(p.atm, o, p.steps, p.spacing, h_g > 0.0f ? dist : -1.0f);
    return c + surface_light(p, e, inside, d, up_g, nrm, p.atm.R0 + h_g, h_g);
}

SB_SKY_TEMPLATE
SKYBAKE_HD_INLINE vec3 shade_surface_approximate(SB_IN(RenderHD) p, SB_SKY_PARAM, vec3 d, vec3 g, vec3 nrm,
                                                 float h_g) {
    ObserverHD o = view_observer(p, d);
    ObserverHD e = o;
    bool inside = enter_atmosphere(p.atm, e);
    vec3 up_g = g / length(g);
    vec3 c = vec3(0.0f);
    if (inside) {
        c = SB_SKY(e.cv, e.cvs, e.cs, component_density(p.atm.comp[0], e.h));
        c = max(c - SB_SKY(dot(up_g, d), o.cvs, dot(up_g, p.sun), component_density(p.atm.comp[0], h_g)),
                vec3(0.0f));
    }
    return c + surface_light(p, e, inside, d, up_g, nrm, p.atm.R0 + h_g, h_g);
}

#endif
