// Per-sample maths of the sky model, shared by the CPU and a CUDA evaluator
// (SKYBAKE_HD), and by the planet renderer's shaders: the functions are in
// sky/sky_shared.h, written once in the common subset of C++ and GLSL; this
// header is their C++ side (the data handles are pointers to flat float
// arrays) and adds what only C++ uses.
#pragma once

#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"
#include "core/shared_source.h"
#include "sky/multiple_hd.h"

namespace skybake::sky {

using glm::vec3;

// sky_shared.h's data handles and texel reads, in C++.
#define SB_DATA const float*
#define SB_TABLE_TEXEL(t, i, j) ((t).L[(i) * (t).cols + (j)])
#define SB_MS_RGB(p, i) vec3((p)[3 * (i)], (p)[3 * (i) + 1], (p)[3 * (i) + 2])

#include "sky/sky_shared.h"

// The graded spacing by default (the shared file has no default arguments).
SKYBAKE_HD_INLINE vec3 seed_sky_sum(const AtmosphereHD& a, const ObserverHD& o, int steps) {
    return seed_sky_sum(a, o, steps, kStepsGraded);
}
SKYBAKE_HD_INLINE vec3 multiple_residual(const AtmosphereHD& a, const ObserverHD& o, int steps) {
    return multiple_residual(a, o, steps, kStepsGraded);
}
SKYBAKE_HD_INLINE vec3 sky_sum(const AtmosphereHD& a, const ObserverHD& o, int steps) {
    return sky_sum(a, o, steps, kStepsGraded);
}

// The single-scattering sum split by component and without the phase
// functions: out[k] = Σ b_k ρ_k T Δv, so that seed_sky_sum = Σ_k P_k(cos β0)
// out[k] (to rounding). With a parallel sun, cos β is the same at every point
// of the view ray, which is what lets a network learn the phase-free parts
// and apply the exact phase functions outside (docs/neural.md).
SKYBAKE_HD_INLINE void seed_sky_sum_split(const AtmosphereHD& a, ObserverHD o, int steps, int spacing,
                                          vec3 out[kMaxComponents]) {
    for (int k = 0; k < kMaxComponents; ++k)
        out[k] = vec3(0.0f);
    if (!enter_atmosphere(a, o))
        return;
    const float len = view_ray_length(a, o);
    if (len <= 0.0f || steps <= 0)
        return;
    const SumState st = sum_state(a, o, false);
    const MarchPlan m = plan_view_ray(a, o, st.base, len, steps, spacing);
    for (int j = 0; j < steps; ++j) {
        float v, dv;
        if (!march_point(m, j, v, dv))
            continue;
        const RayPoint p = ray_point(a, o, st.base, v);
        if (in_planet_shadow(p.r, p.c.sun_zenith, a.R0))
            continue;
        vec3 tau(0.0f), weight[kMaxComponents];
        for (int k = 0; k < a.count; ++k) {
            const ComponentHD& c = a.comp[k];
            const float rho = component_density(c, p.h);
            const float u = table_coordinate(a, c, p.h, rho);
            const float t = st.l_obs[k] - optical_length_lookup(a, c, p.r, u, p.c.view_zenith) +
                            optical_length_lookup(a, c, p.r, u, p.c.sun_zenith);
            tau += c.ext * t;
            weight[k] = c.sca * rho;
        }
        const vec3 T = dv * exp_neg(tau);
        for (int k = 0; k < a.count; ++k)
            out[k] += weight[k] * T;
    }
}

} // namespace skybake::sky
