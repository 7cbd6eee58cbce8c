// What every visibility tracer computes the same way, written once as
// SKYBAKE_HD functions so that the CPU backends, the CUDA kernels and the
// reductions of src/bake/ get the same bits of float: the bit-packed words
// (layout in skybake/visibility.h), a vertex's direction k and its cosine to
// the normal, and which directions need a ray.
#pragma once

#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"

namespace skybake::visibility {

// [SECTION] Bits -------------------------------------------------------------------

SKYBAKE_HD_INLINE std::uint32_t words_for_directions(std::uint32_t directions) {
    return (directions + 31u) / 32u;
}

SKYBAKE_HD_INLINE bool get_bit(const std::uint32_t* words, std::uint32_t k) {
    return (words[k >> 5] >> (k & 31u)) & 1u;
}

SKYBAKE_HD_INLINE void set_bit(std::uint32_t* words, std::uint32_t k) {
    words[k >> 5] |= 1u << (k & 31u);
}

// [SECTION] Directions -------------------------------------------------------------

// Direction k at a vertex: R·x_k for a rotated rule, else x_k (world space).
SKYBAKE_HD_INLINE glm::vec3 rule_direction(const glm::mat3& rotation, bool rotate, const glm::vec3& x) {
    return rotate ? rotation * x : x;
}

// Direction k of a vertex and its cosine to the normal: the one place where
// both are computed, so that every caller gets the same bits of float.
SKYBAKE_HD_INLINE void vertex_direction(const glm::vec3& point, const glm::mat3& rotation, bool rotate,
                                        const glm::vec3& normal, glm::vec3& x, float& cos_n) {
    x = rule_direction(rotation, rotate, point);
    cos_n = glm::dot(normal, x);
}

// Whether a direction needs a ray: on or above the horizon (the seed's V is 0
// below it, so a visibility bit is never set there).
SKYBAKE_HD_INLINE bool needs_ray(float cos_n) {
    return cos_n >= 0.0f;
}

} // namespace skybake::visibility
