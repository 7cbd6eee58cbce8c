// The shading reduction: one vertex's visibility words to its ambient
// occlusion, shading coefficient A and bent normal. SKYBAKE_HD, so that the
// bake driver runs it on the CPU and the CUDA kernel of shading_cuda.cu runs
// it unchanged.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002; docs/SEEDS-DIGEST.md). With the normalised measure dμ = dω/4π and a
// sphere rule {x_k, w_k}:
//     V0 (ambient occlusion) = ∫ V 4(n·x)+ dμ ≈ Σ_k w_k 4 (n·x_k)+ V_k
//     A  (shading coeff.)    = 2 ∫ V dμ        ≈ Σ_k w_k 2 H(n·x_k) V_k
//     bent normal            = normalise(Σ_k w_k V_k (n·x_k)+ x_k)
// where V_k = 1 when direction k is not below the horizon and unblocked, and
// H is the step 1 above, ½ on and 0 below the horizon (see add_direction).
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"
#include "visibility/trace_hd.h"

namespace skybake::bake {

using visibility::get_bit;
using visibility::needs_ray;
using visibility::vertex_direction;

// [SECTION] Reduction -------------------------------------------------------------------
//
// The directions are visited in one fixed order, the rule's coherent order
// (order[j] = k, see coherent_direction_order() in bake/internal.h); the j-th one
// goes to partial sum j mod kReduceLanes, and the partials are added in lane
// order at the end. Every backend follows this order, so all of them get the
// same bits of float from the same visibility, and CPU loops vectorise.

inline constexpr std::uint32_t kReduceLanes = 8;

struct ShadingSums {
    float ao = 0.0f;      // Σ w 4 c V
    float ao_open = 0.0f; // Σ w 4 c      (V ≡ 1)
    float a = 0.0f;       // Σ w 2 V
    float a_open = 0.0f;  // Σ w 2        (V ≡ 1)
    glm::vec3 bent{0.0f}; // Σ w c V x
};

struct ShadingPartials {
    float ao[kReduceLanes] = {}, ao_open[kReduceLanes] = {}, a[kReduceLanes] = {}, a_open[kReduceLanes] = {};
    float bx[kReduceLanes] = {}, by[kReduceLanes] = {}, bz[kReduceLanes] = {};
};

// One direction (x, y, z) (unit, world space) with weight w, cos_n = n·x and
// visible = 1 or 0, into partial `lane`. Below the horizon (cos_n < 0) adds
// nothing; an invisible direction adds to the unoccluded sums only.
//
// Directions exactly on the horizon (cos_n = 0) are traced too and count half
// in A: A's integrand steps there, and symmetric rules (Lebedev, designs) put
// whole orbits on the great circle of an axis-aligned normal (about 3% of the
// weight for lebedev:1202). Leaving them out, as the seed's V = 0 for n·x ≤ 0
// would, biases A low by that much; the midpoint value removes the bias. AO's
// weight (n·x)+ is 0 there anyway.
//
// Written without branches; adding the zero terms leaves the sums unchanged.
SKYBAKE_HD_INLINE void add_direction(ShadingPartials& p, std::uint32_t lane, float w, float cos_n, float x, float y,
                                     float z, float visible) {
    const float up = float(cos_n > 0.0f);
    const float step = 0.5f * (up + float(cos_n >= 0.0f)); // 1 above, ½ on, 0 below the horizon
    const float seen = visible * float(cos_n >= 0.0f);
    const float wc = w * cos_n * up;
    const float ao = 4.0f * wc, a = 2.0f * w * step, b = wc * seen;
    p.ao_open[lane] += ao;
    p.a_open[lane] += a;
    p.ao[lane] += ao * seen;
    p.a[lane] += a * seen;
    p.bx[lane] += b * x;
    p.by[lane] += b * y;
    p.bz[lane] += b * z;
}

SKYBAKE_HD_INLINE ShadingSums combine_partials(const ShadingPartials& p) {
    ShadingSums s;
    for (std::uint32_t l = 0; l < kReduceLanes; ++l) {
        s.ao += p.ao[l];
        s.ao_open += p.ao_open[l];
        s.a += p.a[l];
        s.a_open += p.a_open[l];
        s.bent.x += p.bx[l];
        s.bent.y += p.by[l];
        s.bent.z += p.bz[l];
    }
    return s;
}

struct Shading {
    float ao = 0.0f;
    float shading = 0.0f;
    glm::vec3 bent_normal{0.0f, 0.0f, 1.0f};
    bool clamped = false; // a sum left [0, 1] by more than kClampTolerance and was clamped
};

inline constexpr float kClampTolerance = 1e-6f;

SKYBAKE_HD_INLINE float clamp01(float x, bool& clamped) {
    if (x < -kClampTolerance || x > 1.0f + kClampTolerance)
        clamped = true;
    return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
}

// normalize: divide by the unoccluded sums (see BakeOptions::normalize).
SKYBAKE_HD_INLINE Shading finish_shading(const ShadingSums& s, const glm::vec3& normal, bool normalize) {
    Shading r;
    float ao = s.ao, a = s.a;
    if (normalize) {
        ao = s.ao_open > 0.0f ? s.ao / s.ao_open : 0.0f;
        a = s.a_open > 0.0f ? s.a / s.a_open : 0.0f;
    }
    r.ao = clamp01(ao, r.clamped);
    r.shading = clamp01(a, r.clamped);
    const float len2 = glm::dot(s.bent, s.bent);
    r.bent_normal = len2 > 0.0f ? s.bent * (1.0f / sqrtf(len2)) : normal;
    return r;
}

// The whole reduction for one vertex. words: its visibility words, rule order
// (skybake/visibility.h); points/weights: the rule in single precision, in
// visiting order (points[j] is rule direction order[j]); normal: unit;
// rotation: the vertex's rule rotation (ignored unless rotate). traced, when
// given, receives the count of directions on or above the horizon (the rays).
SKYBAKE_HD_INLINE Shading shading_from_words(const std::uint32_t* words, const glm::vec3* points, const float* weights,
                                             const std::uint32_t* order, std::uint32_t directions,
                                             const glm::vec3& normal, const glm::mat3& rotation, bool rotate,
                                             bool normalize, std::uint32_t* traced = nullptr) {
    ShadingPartials p;
    std::uint32_t rays = 0;
    for (std::uint32_t j0 = 0; j0 < directions; j0 += kReduceLanes)
        for (std::uint32_t l = 0; l < kReduceLanes && j0 + l < directions; ++l) {
            const std::uint32_t j = j0 + l;
            glm::vec3 x;
            float c;
            vertex_direction(points[j], rotation, rotate, normal, x, c);
            add_direction(p, l, weights[j], c, x.x, x.y, x.z, get_bit(words, order[j]) ? 1.0f : 0.0f);
            rays += needs_ray(c) ? 1u : 0u;
        }
    if (traced)
        *traced = rays;
    return finish_shading(combine_partials(p), normal, normalize);
}

} // namespace skybake::bake
