// Texture-space ambient occlusion: texel centres of a UV layout as the bake's
// sample points, conservative coverage, gutter dilation.
//
// Coverage: Akenine-Möller & Aila, "Conservative and Tiled Rasterization
// Using a Modified Triangle Setup", journal of graphics tools 10(3), 2005:
// a pixel square overlaps a triangle unless one of the three edges (or the
// bounding box) separates them, the edge test taken at the square's corner
// furthest inside. Visibility and its reduction are the vertex bake's
// (Svistunov, seed 002), at these points instead of the vertices.
#include "skybake/texture_bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/error.h"

namespace skybake {

namespace {

constexpr int kMinSize = kMinTextureSize, kMaxSize = kMaxTextureSize, kMaxDilate = 256;
constexpr float kNoTriangle = std::numeric_limits<float>::infinity();

double cross2(glm::dvec2 a, glm::dvec2 b) {
    return a.x * b.y - a.y * b.x;
}

// The closest point to c on segment [a, b].
glm::dvec2 closest_on_segment(glm::dvec2 c, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(c - a, ab) / len2, 0.0, 1.0) : 0.0;
    return a + t * ab;
}

// Barycentric coordinates of p in triangle (a, b, c) with signed area2 = cross(b - a, c - a).
glm::dvec3 barycentric(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double area2) {
    const double l1 = cross2(c - b, p - b) / area2, l2 = cross2(a - c, p - c) / area2;
    return {l1, l2, 1.0 - l1 - l2};
}

} // namespace

TexelSamples texel_samples(const Mesh& mesh, const TextureBakeOptions& options) {
    validate_mesh(mesh, "mesh");
    const int size = options.texture_size;
    if (size < kMinSize || size > kMaxSize)
        throw Error(fmt::format("texture size must be {} to {} texels; got {}", kMinSize, kMaxSize, size),
                    "texture_size");
    if (options.dilate_texels < 0 || options.dilate_texels > kMaxDilate)
        throw Error(fmt::format("gutter must be 0 to {} texels; got {}", kMaxDilate, options.dilate_texels),
                    "dilate_texels");
    if (options.uv_set < 0 || std::size_t(options.uv_set) >= mesh.texcoords.size())
        throw Error(mesh.texcoords.empty()
                        ? std::string("the mesh has no UVs; a texture bake needs a UV layout (TEXCOORD_n)")
                        : fmt::format("the mesh has UV sets 0 to {}; there is no set {}", mesh.texcoords.size() - 1,
                                      options.uv_set),
                    "uv_set");
    if (mesh.normals.size() != mesh.vertex_count())
        throw Error("the mesh has no vertex normals; compute them first (compute_normals)", "mesh");
    const std::vector<glm::vec2>& uv = mesh.texcoords[std::size_t(options.uv_set)];
    for (std::size_t v = 0; v < uv.size(); ++v)
        if (!(uv[v].x >= 0.0f && uv[v].x <= 1.0f && uv[v].y >= 0.0f && uv[v].y <= 1.0f))
            throw Error(fmt::format("UV set {} has ({}, {}) at vertex {}, outside [0, 1]; a texture bake needs a "
                                    "layout inside the unit square (no tiling or UDIMs)",
                                    options.uv_set, uv[v].x, uv[v].y, v),
                        "uv_set");

    // Per texel: the owning triangle, its barycentrics, the distance from the
    // texel centre to it (0 inside), and how many triangles hold the centre.
    const std::size_t texel_count = std::size_t(size) * std::size_t(size);
    std::vector<std::uint32_t> owner(texel_count, 0);
    std::vector<float> distance(texel_count, kNoTriangle);
    std::vector<glm::vec2> bary(texel_count);
    std::vector<std::uint8_t> inside(texel_count, 0);
    std::vector<std::uint8_t> triangle_overlaps(mesh.triangle_count(), 0);
    std::vector<std::uint32_t> first_inside(texel_count, 0);

    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t* i = &mesh.indices[3 * t];
        const glm::dvec2 p[3] = {glm::dvec2(uv[i[0]]) * double(size), glm::dvec2(uv[i[1]]) * double(size),
                                 glm::dvec2(uv[i[2]]) * double(size)};
        const double area2 = cross2(p[1] - p[0], p[2] - p[0]);
        if (!(std::abs(area2) > 1e-12))
            continue;                              // no UV footprint
        const double s = area2 > 0.0 ? 1.0 : -1.0; // inside: s · cross(edge, q - start) ≥ 0
        const glm::dvec2 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
        const int x0 = std::clamp(int(std::floor(lo.x)), 0, size - 1),
                  x1 = std::clamp(int(std::floor(hi.x)), 0, size - 1);
        const int y0 = std::clamp(int(std::floor(lo.y)), 0, size - 1),
                  y1 = std::clamp(int(std::floor(hi.y)), 0, size - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                // Separating axis test of the square [x, x+1] × [y, y+1] against each edge.
                bool overlaps = true;
                for (int e = 0; e < 3 && overlaps; ++e) {
                    const glm::dvec2 a = p[e], d = p[(e + 1) % 3] - a;
                    // The inward normal of the edge is s · (-d.y, d.x); its most inside corner:
                    const glm::dvec2 nrm = s * glm::dvec2(-d.y, d.x);
                    const glm::dvec2 corner(x + (nrm.x > 0.0 ? 1.0 : 0.0), y + (nrm.y > 0.0 ? 1.0 : 0.0));
                    overlaps = glm::dot(nrm, corner - a) >= 0.0;
                }
                if (!overlaps)
                    continue;
                const glm::dvec2 c(x + 0.5, y + 0.5);
                glm::dvec3 l = barycentric(c, p[0], p[1], p[2], area2);
                double dist = 0.0;
                const double inner = std::min({l.x, l.y, l.z});
                if (inner < 0.0) { // centre outside: the closest point, a little inside
                    glm::dvec2 best = closest_on_segment(c, p[0], p[1]);
                    for (int e = 1; e < 3; ++e) {
                        const glm::dvec2 q = closest_on_segment(c, p[e], p[(e + 1) % 3]);
                        if (glm::dot(q - c, q - c) < glm::dot(best - c, best - c))
                            best = q;
                    }
                    dist = glm::length(best - c);
                    l = barycentric(best, p[0], p[1], p[2], area2);
                    l = glm::clamp(l, 0.0, 1.0);
                    l /= l.x + l.y + l.z;
                    l = 0.999 * l + glm::dvec3(0.001 / 3.0);
                }
                const std::size_t k = std::size_t(y) * std::size_t(size) + std::size_t(x);
                if (inner > 1e-6) { // strictly inside
                    if (inside[k] == 1)
                        triangle_overlaps[first_inside[k]] = triangle_overlaps[t] = 1;
                    else
                        first_inside[k] = std::uint32_t(t);
                    inside[k] = std::uint8_t(std::min(inside[k] + 1, 255));
                }
                if (dist < distance[k]) {
                    distance[k] = float(dist);
                    owner[k] = std::uint32_t(t);
                    bary[k] = glm::vec2(float(l.x), float(l.y));
                }
            }
    }

    TexelSamples out;
    out.texture_size = size;
    for (std::size_t k = 0; k < texel_count; ++k) {
        if (distance[k] == kNoTriangle)
            continue;
        out.texels.push_back(std::uint32_t(k));
        out.overlapping_texels += inside[k] > 1;
    }
    if (out.texels.empty())
        throw Error(fmt::format("UV set {} covers no texel: every triangle's UV footprint has zero area, so the "
                                "texture would stay blank; unwrap the mesh (for example Smart UV Project in Blender)",
                                options.uv_set),
                    "uv_set");
    for (std::uint8_t o : triangle_overlaps)
        out.overlapping_triangles += o;
    const std::size_t n = out.texels.size();
    out.points.positions.resize(n);
    out.points.normals.resize(n);
    out.points.sizes.resize(n);
    parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t j = b; j < e; ++j) {
            const std::size_t k = out.texels[j];
            const std::uint32_t* i = &mesh.indices[3 * std::size_t(owner[k])];
            const float l0 = bary[k].x, l1 = bary[k].y, l2 = 1.0f - l0 - l1;
            const glm::vec3 a = mesh.positions[i[0]], bpos = mesh.positions[i[1]], c = mesh.positions[i[2]];
            out.points.positions[j] = l0 * a + l1 * bpos + l2 * c;
            const glm::vec3 face = glm::cross(bpos - a, c - a);
            glm::vec3 nrm = l0 * mesh.normals[i[0]] + l1 * mesh.normals[i[1]] + l2 * mesh.normals[i[2]];
            const float len = glm::length(nrm);
            nrm = len > 1e-6f && std::isfinite(len) ? nrm / len : glm::normalize(face);
            out.points.normals[j] = nrm;
            // One texel's size on the surface: sqrt(world area / UV area in texels).
            const glm::vec2 ua = uv[i[0]] * float(size), ub = uv[i[1]] * float(size), uc = uv[i[2]] * float(size);
            const float uv_area = std::abs(float(cross2(ub - ua, uc - ua)));
            out.points.sizes[j] = uv_area > 0.0f ? std::sqrt(glm::length(face) / uv_area) : 0.0f;
        }
    });
    return out;
}

AoTexture bake_ao_texture(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                          const BakeOptions& options, const TextureBakeOptions& texture) {
    const auto t0 = std::chrono::steady_clock::now();
    const TexelSamples samples = texel_samples(mesh, texture);
    AoTexture out;
    out.sample_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.texture_size = samples.texture_size;
    out.covered_texels = samples.texels.size();
    out.overlapping_texels = samples.overlapping_texels;
    out.overlapping_triangles = samples.overlapping_triangles;

    BakeOutputs baked;
    BakeOptions o = options;
    o.store_bits = false;
    ShadingReduction reduction(baked, o.normalize, false);
    const VisibilityBakeStats stats = bake_visibility(mesh, samples.points, rule, tracer, o, reduction);
    out.rays = stats.rays;
    out.build_seconds = stats.build_seconds;
    out.trace_seconds = stats.trace_seconds;

    const std::size_t texel_count = std::size_t(out.texture_size) * std::size_t(out.texture_size);
    out.ao.assign(texel_count, 1.0f);
    out.coverage.assign(texel_count, 0);
    for (std::size_t j = 0; j < samples.texels.size(); ++j) {
        out.ao[samples.texels[j]] = baked.ao[j];
        out.coverage[samples.texels[j]] = 1;
    }
    dilate_texture(out.ao, out.coverage, out.texture_size, texture.dilate_texels);
    if (texture.stitch_seams)
        out.seams = stitch_texture_seams(mesh, texture.uv_set, out.ao, out.texture_size);
    return out;
}

void dilate_texture(std::vector<float>& values, std::vector<std::uint8_t>& coverage, int size, int texels) {
    const std::size_t count = std::size_t(size) * std::size_t(size);
    if (values.size() != count || coverage.size() != count)
        throw Error(
            fmt::format("{} values and {} coverage entries for a {}² texture", values.size(), coverage.size(), size),
            "values");
    std::vector<std::uint32_t> ring;
    std::vector<float> fill;
    for (int pass = 0; pass < texels; ++pass) {
        ring.clear();
        fill.clear();
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const std::size_t k = std::size_t(y) * std::size_t(size) + std::size_t(x);
                if (coverage[k])
                    continue;
                double sum = 0.0;
                int n = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int xx = x + dx, yy = y + dy;
                        if ((dx || dy) && xx >= 0 && yy >= 0 && xx < size && yy < size) {
                            const std::size_t q = std::size_t(yy) * std::size_t(size) + std::size_t(xx);
                            if (coverage[q]) {
                                sum += values[q];
                                ++n;
                            }
                        }
                    }
                if (n) {
                    ring.push_back(std::uint32_t(k));
                    fill.push_back(float(sum / n));
                }
            }
        if (ring.empty())
            break;
        for (std::size_t j = 0; j < ring.size(); ++j) {
            values[ring[j]] = fill[j];
            coverage[ring[j]] = 2;
        }
    }
}

float sample_texture(const AoTexture& texture, glm::vec2 uv) {
    const int size = texture.texture_size;
    const float fx = std::clamp(uv.x * float(size) - 0.5f, 0.0f, float(size - 1));
    const float fy = std::clamp(uv.y * float(size) - 0.5f, 0.0f, float(size - 1));
    const int x0 = int(fx), y0 = int(fy);
    const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
    const float tx = fx - float(x0), ty = fy - float(y0);
    auto at = [&](int x, int y) { return texture.ao[std::size_t(y) * std::size_t(size) + std::size_t(x)]; };
    return (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) + ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1));
}

} // namespace skybake
