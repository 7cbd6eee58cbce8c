// Deterministic per-vertex random rotations, shared by the CPU and CUDA bakers.
//
// Shoemake K. Uniform random rotations. Graphics Gems III, 1992: three uniform
// numbers give a uniformly distributed unit quaternion. The numbers come from a
// hash of (vertex, seed) (splitmix64 finaliser, Steele et al. 2014), so the
// rotation of a vertex does not depend on the order or the thread that asks.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/mat3x3.hpp>

#include "core/hd.h"
#include "core/random.h"

namespace skybake::sphere {

using skybake::splitmix64;
using skybake::unit_double;

// Rotation matrix R (apply as R * x) for one vertex; uniform over SO(3).
template <class T>
SKYBAKE_HD_INLINE glm::mat<3, 3, T> vertex_rotation_hd(std::uint32_t vertex, std::uint64_t seed) {
    const std::uint64_t h0 = splitmix64(seed ^ (std::uint64_t(vertex) * 0xd1b54a32d192ed03ull));
    const std::uint64_t h1 = splitmix64(h0);
    const std::uint64_t h2 = splitmix64(h1);
    const double u1 = unit_double(h0), u2 = unit_double(h1), u3 = unit_double(h2);
    const double two_pi = 6.283185307179586;
    const double r1 = sqrt(1.0 - u1), r2 = sqrt(u1);
    const double qx = r1 * sin(two_pi * u2), qy = r1 * cos(two_pi * u2);
    const double qz = r2 * sin(two_pi * u3), qw = r2 * cos(two_pi * u3);
    // glm matrices are column-major: m[column][row].
    glm::mat<3, 3, T> m;
    m[0][0] = T(1 - 2 * (qy * qy + qz * qz));
    m[0][1] = T(2 * (qx * qy + qz * qw));
    m[0][2] = T(2 * (qx * qz - qy * qw));
    m[1][0] = T(2 * (qx * qy - qz * qw));
    m[1][1] = T(1 - 2 * (qx * qx + qz * qz));
    m[1][2] = T(2 * (qy * qz + qx * qw));
    m[2][0] = T(2 * (qx * qz + qy * qw));
    m[2][1] = T(2 * (qy * qz - qx * qw));
    m[2][2] = T(1 - 2 * (qx * qx + qy * qy));
    return m;
}

} // namespace skybake::sphere
