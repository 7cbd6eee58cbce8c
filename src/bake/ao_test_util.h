// Closed forms and exact-geometry references for the AO tests.
//
// Two independent references for a bake:
//  - the closed form of the integral (REFERENCE.md, "Ambient occlusion"), and
//  - the same sphere rule applied to the exact visibility of the ideal shape,
//    decided analytically per direction (no mesh, no ray tracer).
// bake − rule_exact is the tessellation and ray-tracing error; rule_exact −
// closed form is the quadrature error of the rule alone.
#pragma once

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "skybake/mesh.h"
#include "skybake/sphere.h"

namespace skybake::ao_test {

constexpr double kPi = 3.14159265358979323846;

// Form factor from a differential area at p with unit normal n to a planar
// polygon (counter-clockwise or clockwise) lying wholly above p's tangent
// plane: Lambert's formula (Baum, Rushmeier & Winget 1989, eq. 4):
//   F = (1/2π) |Σ_i γ_i n · (r_i × r_{i+1}) / |r_i × r_{i+1}||,
// with r_i = v_i − p and γ_i the angle between r_i and r_{i+1}.
inline double polygon_form_factor(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::dvec3>& poly) {
    double sum = 0.0;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 a = glm::normalize(poly[i] - p), b = glm::normalize(poly[(i + 1) % poly.size()] - p);
        const glm::dvec3 c = glm::cross(a, b);
        const double len = glm::length(c);
        if (len == 0.0)
            continue;
        const double gamma = std::atan2(len, glm::dot(a, b));
        sum += gamma * glm::dot(n, c) / len;
    }
    return std::abs(sum) / (2.0 * kPi);
}

// Solid angle of a triangle seen from p (Van Oosterom & Strackee 1983).
inline double triangle_solid_angle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 r1 = a - p, r2 = b - p, r3 = c - p;
    const double l1 = glm::length(r1), l2 = glm::length(r2), l3 = glm::length(r3);
    const double num = std::abs(glm::dot(r1, glm::cross(r2, r3)));
    const double den = l1 * l2 * l3 + glm::dot(r1, r2) * l3 + glm::dot(r1, r3) * l2 + glm::dot(r2, r3) * l1;
    double omega = 2.0 * std::atan2(num, den);
    if (omega < 0.0)
        omega += 4.0 * kPi;
    return omega;
}

// Solid angle of a convex planar polygon (fan from vertex 0).
inline double polygon_solid_angle(const glm::dvec3& p, const std::vector<glm::dvec3>& poly) {
    double s = 0.0;
    for (std::size_t i = 1; i + 1 < poly.size(); ++i)
        s += triangle_solid_angle(p, poly[0], poly[i], poly[i + 1]);
    return s;
}

struct Coefficients {
    double ao = 0.0, shading = 0.0;
    glm::dvec3 bent{0.0}; // Σ_k w_k (n·x_k)+ V(x_k) x_k, not normalised
};

// Σ_k w_k 4(n·x_k)+ V(x_k), Σ_k w_k 2 H(n·x_k) V(x_k) (H: 1 above, ½ on
// the horizon) and the bent normal's sum Σ_k w_k (n·x_k)+ V(x_k) x_k, for an exact visibility function V(x) (1 = open): the bake's
// sums (skybake/visibility.h) with the ideal shape in place of the mesh.
template <class V>
Coefficients rule_exact(const SphereRule& rule, const glm::dvec3& n, V&& visible) {
    Coefficients c;
    for (std::size_t k = 0; k < rule.size(); ++k) {
        const double cn = glm::dot(n, rule.points[k]);
        if (cn < 0.0 || !visible(rule.points[k]))
            continue;
        c.ao += 4.0 * rule.weights[k] * cn;
        c.shading += (cn > 0.0 ? 2.0 : 1.0) * rule.weights[k];
        c.bent += rule.weights[k] * cn * rule.points[k];
    }
    return c;
}

// The rule turned by vertex v's rotation when it asks for one.
inline SphereRule turned_rule(const SphereRule& rule, std::uint32_t v) {
    if (!rule.rotate_per_vertex)
        return rule;
    SphereRule r = rule;
    const glm::dmat3 R = vertex_rotation(v, rule.rotation_seed);
    for (auto& x : r.points)
        x = R * x;
    return r;
}

// Visibility inside the unit hemispherical bowl (y ≤ 0) from a point p on it:
// the ray leaves the sphere at p + t x with t = −2 p·x; it escapes through
// the opening when that exit point has y > 0.
inline bool bowl_visible(const glm::dvec3& p, const glm::dvec3& x) {
    const double t = -2.0 * glm::dot(p, x);
    return p.y + t * x.y > 0.0;
}

// Visibility from a floor point p (y = 0) past the rectangle
// x ∈ [x0, x1], y ∈ [0, h] in the plane z = zw (< p.z).
inline bool wall_visible(const glm::dvec3& p, const glm::dvec3& x, double x0, double x1, double h, double zw) {
    if (x.z >= 0.0)
        return true;
    const double t = (zw - p.z) / x.z;
    const double hx = p.x + t * x.x, hy = p.y + t * x.y;
    return !(hx >= x0 && hx <= x1 && hy >= 0.0 && hy <= h);
}

// A procedural mesh of about `triangles` triangles, default seed.
inline Mesh generated(ProceduralKind kind, std::uint64_t triangles) {
    ProceduralOptions p;
    p.kind = kind;
    p.target_triangles = triangles;
    return generate_mesh(p);
}

} // namespace skybake::ao_test
