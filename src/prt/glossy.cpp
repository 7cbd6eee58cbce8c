// Glossy transfer with weighted designs of the Phong lobe.
//
// Svistunov (seed 002, after the author's DPRT): B̃(v) ≈ Σ_k λ_k L(g_nv x_k),
// {x_k, λ_k} a rule for the weight of the Phong lobe, g_nv the rotation that
// takes the lobe axis to the mirror direction. See skybake/prt.h, [SECTION]
// Glossy transfer (DPRT).
#include <cmath>

#include <glm/geometric.hpp>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {

glm::mat3 frame_from_axis(const glm::vec3& axis) {
    // Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
    const float sign = std::copysign(1.0f, axis.z);
    const float a = -1.0f / (sign + axis.z);
    const float b = axis.x * axis.y * a;
    const glm::vec3 t(1.0f + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
    const glm::vec3 u(b, sign + axis.y * axis.y * a, -axis.y);
    return glm::mat3(t, u, axis);
}

glm::vec3 mirror_direction(const glm::vec3& n, const glm::vec3& v) {
    return 2.0f * glm::dot(n, v) * n - v;
}

glm::vec3 dprt_glossy(const SphereRule& phong, const std::function<glm::vec3(const glm::vec3&)>& radiance,
                      const glm::vec3& normal, const glm::vec3& view) {
    const glm::mat3 g = frame_from_axis(glm::normalize(mirror_direction(normal, view)));
    glm::dvec3 sum(0.0);
    for (std::size_t k = 0; k < phong.size(); ++k)
        sum += phong.weights[k] * glm::dvec3(radiance(g * glm::vec3(phong.points[k])));
    return glm::vec3(sum);
}

glm::vec3 dprt_glossy(const SphereRule& phong, const ShLight& light, const glm::vec3& normal, const glm::vec3& view) {
    const std::vector<glm::dvec3> c(light.coeffs.begin(), light.coeffs.end());
    return dprt_glossy(
        phong, [&](const glm::vec3& x) { return glm::vec3(sh_evaluate(c, light.order, glm::dvec3(x))); }, normal, view);
}

glm::vec3 phong_glossy_exact(const ShLight& light, double a, const glm::vec3& normal, const glm::vec3& view) {
    if (!(a >= 0.0))
        throw Error("the Phong exponent must be ≥ 0", "exponent");
    const glm::dvec3 r = glm::normalize(glm::dvec3(mirror_direction(normal, view)));
    std::vector<double> y(std::size_t(sh_count(light.order)));
    sh_eval(light.order, r, y.data());
    glm::dvec3 sum(0.0);
    for (int l = 0; l <= light.order; ++l) {
        const double k = 2.0 * (a + 1.0) / (4.0 * M_PI) * phong_lobe_zonal(l, a);
        for (int m = -l; m <= l; ++m)
            sum += k * y[std::size_t(sh_index(l, m))] * glm::dvec3(light.coeffs[std::size_t(sh_index(l, m))]);
    }
    return glm::vec3(sum);
}

} // namespace skybake
