// Ray–triangle intersection shared by the brute-force oracle and the CUDA
// backend's traversal (SKYBAKE_HD: the same test on the CPU and the GPU).
//
// Möller T., Trumbore B. Fast, minimum storage ray-triangle intersection.
// Journal of Graphics Tools 2(1), 1997.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"

namespace skybake::visibility {

// Triangle p0, p1 = p0 + e1, p2 = p0 + e2. Returns true and the distance t and
// barycentrics (u, v) of p1 and p2 when the ray o + t·d meets it with
// t_min < t ≤ t_max (a hit exactly at t_min, e.g. at the origin, does not count). Edges and vertices count as inside (u, v ≥ 0, u + v ≤ 1),
// so a ray through a shared edge hits one of its triangles. Rays parallel to
// the plane (det = 0) miss, and so do degenerate triangles.
// cull_back: a triangle met from behind misses too. det = d · (e2 × e1) is
// negative exactly when d points along the front normal e1 × e2.
template <class T>
SKYBAKE_HD_INLINE bool ray_triangle(const glm::vec<3, T>& o, const glm::vec<3, T>& d, const glm::vec<3, T>& p0,
                                    const glm::vec<3, T>& e1, const glm::vec<3, T>& e2, T t_min, T t_max, T& t,
                                    T& u, T& v, bool cull_back = false) {
    const glm::vec<3, T> pvec = glm::cross(d, e2);
    const T det = glm::dot(e1, pvec);
    if (det == T(0) || (cull_back && det < T(0)))
        return false;
    const T inv = T(1) / det;
    const glm::vec<3, T> tvec = o - p0;
    u = glm::dot(tvec, pvec) * inv;
    if (!(u >= T(0) && u <= T(1)))
        return false;
    const glm::vec<3, T> qvec = glm::cross(tvec, e1);
    v = glm::dot(d, qvec) * inv;
    if (!(v >= T(0) && u + v <= T(1)))
        return false;
    t = glm::dot(e2, qvec) * inv;
    return t > t_min && t <= t_max;
}

} // namespace skybake::visibility
