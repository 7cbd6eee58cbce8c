// Relighting of a baked transfer: B = ρ Σ L_lm T_lm, plus the sun as a direct
// light (Sloan, Kautz & Snyder 2002, section 4: one dot product per vertex).
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "bake/preview.h"
#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {

std::vector<glm::vec3> relight(const Transfer& transfer, const ShLight& light, std::span<const glm::vec3> albedo,
                               std::span<const glm::vec3> normals, std::span<const float> sun_visible) {
    const std::size_t n = transfer.vertices();
    const int nc = transfer.coefficients;
    if (light.order < transfer.order || light.coeffs.size() < std::size_t(nc))
        throw Error(fmt::format("the light has SH order {} but the transfer needs {}; project the light with "
                                "--order {} or more",
                                light.order, transfer.order, transfer.order),
                    "light");
    if (albedo.size() != n)
        throw Error(fmt::format("{} albedo values for {} vertices", albedo.size(), n), "albedo");
    const bool sun = !normals.empty();
    if (sun && (normals.size() != n || sun_visible.size() != n))
        throw Error("the sun needs one normal and one visibility per vertex", "light");
    std::vector<glm::vec3> out(n);
    parallel_for(n, 1024, [&](std::size_t b, std::size_t e) {
        for (std::size_t v = b; v < e; ++v) {
            glm::vec3 sum(0.0f);
            if (transfer.channels == 1) {
                const float* t = transfer.vertex(v);
                for (int i = 0; i < nc; ++i)
                    sum += light.coeffs[std::size_t(i)] * t[i];
            } else {
                for (int ch = 0; ch < 3; ++ch) {
                    const float* t = transfer.vertex(v, ch);
                    float s = 0.0f;
                    for (int i = 0; i < nc; ++i)
                        s += light.coeffs[std::size_t(i)][ch] * t[i];
                    sum[ch] = s;
                }
            }
            if (sun)
                sum += light.sun_irradiance *
                       float(std::max(0.0f, glm::dot(normals[v], light.sun_direction)) * sun_visible[v] / M_PI);
            out[v] = albedo[v] * sum;
        }
    });
    return out;
}

std::vector<float> sun_visibility(const Mesh& mesh, const glm::vec3& sun_direction, RayQueries& queries) {
    const std::vector<std::uint8_t> lit = direction_visibility(mesh, sun_direction, BakeOptions{}, queries);
    return std::vector<float>(lit.begin(), lit.end());
}

Image render_prt_preview(const Mesh& mesh, const Transfer& transfer, std::span<const glm::vec3> diffuse,
                         const ShLight& light, double phong_exponent, float specular, const AoPreviewOptions& options) {
    validate_mesh(mesh, "mesh");
    const std::size_t n = mesh.vertex_count();
    if (diffuse.size() != n)
        throw Error(fmt::format("{} radiance values for {} vertices", diffuse.size(), n), "mesh");
    if (!(phong_exponent >= 0.0) || !std::isfinite(phong_exponent))
        throw Error(fmt::format("the Phong exponent must be ≥ 0; got {}", phong_exponent), "exponent");
    const bool glossy = phong_exponent > 0.0 && specular > 0.0f;
    std::vector<glm::vec3> normals = bake_vertex_normals(mesh);
    const SphereRule rule = glossy ? phong_rule(phong_exponent, light.order / 2 + 1) : SphereRule{};
    const std::vector<glm::dvec3> c(light.coeffs.begin(), light.coeffs.end());
    const bool have_a = transfer.shading.size() == n;
    return bake::render_preview(
        mesh, options,
        [&](const std::uint32_t* t, float u, float v, const glm::vec3& dir) {
            const float w0 = 1.0f - u - v;
            glm::vec3 rgb = w0 * diffuse[t[0]] + u * diffuse[t[1]] + v * diffuse[t[2]];
            if (!glossy)
                return rgb;
            glm::vec3 nrm = w0 * normals[t[0]] + u * normals[t[1]] + v * normals[t[2]];
            const float len = glm::length(nrm);
            if (!(len > 0.0f))
                return rgb;
            nrm /= len;
            const glm::vec3 view = -dir;
            if (glm::dot(nrm, view) < 0.0f)
                nrm = -nrm; // seen from behind
            const float a =
                have_a ? w0 * transfer.shading[t[0]] + u * transfer.shading[t[1]] + v * transfer.shading[t[2]] : 1.0f;
            const glm::vec3 g = dprt_glossy(
                rule,
                [&](const glm::vec3& x) {
                    return glm::max(glm::vec3(sh_evaluate(c, light.order, glm::dvec3(x))), 0.0f);
                },
                nrm, view);
            return rgb + specular * a * g;
        },
        [&](const glm::vec3& dir) { return glm::max(glm::vec3(sh_evaluate(c, light.order, glm::dvec3(dir))), 0.0f); });
}

} // namespace skybake
