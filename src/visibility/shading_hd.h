// Shading coefficients from per-direction visibility, shared by every backend
// (CPU now, CUDA kernels later: everything here is SKYBAKE_HD).
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002; docs/SEEDS-DIGEST.md). With the normalised measure dμ = dω/4π and a
// sphere rule {x_k, w_k}:
//     V0 (ambient occlusion) = ∫ V 4(n·x)+ dμ ≈ Σ_k w_k 4 (n·x_k)+ V_k
//     A  (shading coeff.)    = 2 ∫ V dμ        ≈ Σ_k w_k 2 [n·x_k > 0] V_k
//     bent normal            = normalise(Σ_k w_k V_k (n·x_k)+ x_k)
// where V_k = 1 when direction k is above the horizon and unblocked. The seed's
// V is 0 below the horizon, so a visibility bit is never set there.
//
// Bit layout (also in skybake/visibility.h): uint32 words, direction k is bit
// k % 32 of word k / 32; the seed used uint16 words of 16 directions.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"

namespace skybake::visibility {

// [SECTION] Bits -------------------------------------------------------------------

SKYBAKE_HD_INLINE std::uint32_t words_for_directions(std::uint32_t directions) { return (directions + 31u) / 32u; }

SKYBAKE_HD_INLINE bool get_bit(const std::uint32_t* words, std::uint32_t k) { return (words[k >> 5] >> (k & 31u)) & 1u; }

SKYBAKE_HD_INLINE void set_bit(std::uint32_t* words, std::uint32_t k) { words[k >> 5] |= 1u << (k & 31u); }

// [SECTION] Per-vertex ray set-up -------------------------------------------------------

// Direction k at a vertex: R·x_k for a rotated rule, else x_k (world space).
SKYBAKE_HD_INLINE glm::vec3 rule_direction(const glm::mat3& rotation, bool rotate, const glm::vec3& x) {
    return rotate ? rotation * x : x;
}

// Ray origin: the vertex moved by `offset` (mesh units) along its unit normal.
SKYBAKE_HD_INLINE glm::vec3 ray_origin(const glm::vec3& position, const glm::vec3& normal, float offset) {
    return position + offset * normal;
}

// [SECTION] Reduction -------------------------------------------------------------------

struct ShadingSums {
    float ao = 0.0f;      // Σ w 4 c V
    float ao_open = 0.0f; // Σ w 4 c      (V ≡ 1)
    float a = 0.0f;       // Σ w 2 V
    float a_open = 0.0f;  // Σ w 2        (V ≡ 1)
    glm::vec3 bent{0.0f}; // Σ w c V x
};

// One direction x (unit, world space) with weight w and cos_n = n·x > 0.
SKYBAKE_HD_INLINE void add_direction(ShadingSums& s, float w, float cos_n, const glm::vec3& x, bool visible) {
    const float wc = w * cos_n;
    s.ao_open += 4.0f * wc;
    s.a_open += 2.0f * w;
    if (visible) {
        s.ao += 4.0f * wc;
        s.a += 2.0f * w;
        s.bent += wc * x;
    }
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

// The whole reduction for one vertex, from its visibility words (direction
// order k = 0 ... K−1). points/weights: the rule in single precision; normal:
// unit; rotation: the vertex's rule rotation (ignored unless rotate).
SKYBAKE_HD_INLINE Shading shading_from_bits(const std::uint32_t* words, const glm::vec3* points, const float* weights,
                                            std::uint32_t directions, const glm::vec3& normal,
                                            const glm::mat3& rotation, bool rotate, bool normalize) {
    ShadingSums s;
    for (std::uint32_t k = 0; k < directions; ++k) {
        const glm::vec3 x = rule_direction(rotation, rotate, points[k]);
        const float c = glm::dot(normal, x);
        if (c > 0.0f)
            add_direction(s, weights[k], c, x, get_bit(words, k));
    }
    return finish_shading(s, normal, normalize);
}

} // namespace skybake::visibility
