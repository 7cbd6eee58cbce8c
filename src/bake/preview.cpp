// Preview of a baked mesh: primary rays from a pinhole camera (Embree), each
// hit shaded by the baked per-vertex AO interpolated with the hit's
// barycentrics. The AO is shown as a display value (PNG grey level 255·AO),
// which reads better than AO as linear light.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "bake/preview.h"
#include "skybake/bake.h"
#include "skybake/error.h"
#include "skybake/texture_bake.h"

namespace skybake {

PreviewCamera preview_camera(const Mesh& mesh, const AoPreviewOptions& o) {
    // Camera framing the bounding sphere of the bounding box, y up.
    const Bounds b = compute_bounds(mesh);
    PreviewCamera c;
    c.centre = 0.5f * (b.min + b.max);
    c.radius = std::max(0.5f * b.diagonal(), 1e-20f);
    const float deg = 3.14159265358979f / 180.0f;
    const float az = o.azimuth_deg * deg, el = o.elevation_deg * deg;
    const glm::vec3 to_eye(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    const float half = 0.5f * o.fov_y_deg * deg;
    c.aspect = float(o.width) / float(o.height);
    const float fit = std::min(std::sin(half), std::sin(std::atan(std::tan(half) * c.aspect)));
    c.eye = c.centre + to_eye * (c.radius / fit * 1.02f);
    c.forward = -to_eye;
    glm::vec3 up_hint(0.0f, 1.0f, 0.0f);
    if (std::abs(glm::dot(c.forward, up_hint)) > 0.999f)
        up_hint = glm::vec3(0.0f, 0.0f, -1.0f);
    c.right = glm::normalize(glm::cross(c.forward, up_hint));
    c.up = glm::cross(c.right, c.forward);
    c.tan_half_fov_y = std::tan(half);
    return c;
}

Image bake::render_preview(const Mesh& mesh, const AoPreviewOptions& o, const bake::PreviewShader& shade,
                           const bake::PreviewBackground& sky) {
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
        throw Error(fmt::format("preview size {}x{} is out of range; use 1 to 16384 pixels per side", o.width, o.height),
                    "width, height");
    if (o.samples < 1 || o.samples > 8)
        throw Error(fmt::format("{} samples per pixel axis is out of range; use 1 to 8", o.samples), "samples");
    if (!(o.fov_y_deg > 1.0f && o.fov_y_deg < 170.0f))
        throw Error(fmt::format("field of view {} degrees is out of range; use 1 to 170", o.fov_y_deg), "fov_y_deg");

    std::unique_ptr<RayQueries> own;
    const RayQueries* backend = o.queries;
    if (!backend) {
        own = make_ray_queries("embree");
        own->set_mesh(mesh, BackFaces::Occlude);
        backend = own.get();
    }

    const PreviewCamera cam = preview_camera(mesh, o);
    const glm::vec3 eye = cam.eye, forward = cam.forward, right = cam.right, up = cam.up;
    const float th = cam.tan_half_fov_y, aspect = cam.aspect;

    const glm::vec3 background(0.035f, 0.045f, 0.065f);
    Image img(o.width, o.height);
    const int s = o.samples;
    const std::size_t row_rays = std::size_t(o.width) * std::size_t(s * s);
    const int rows_per_block = 32;
    std::vector<Ray> rays;
    std::vector<RayHit> hits;
    for (int y0 = 0; y0 < o.height; y0 += rows_per_block) {
        const int y1 = std::min(o.height, y0 + rows_per_block);
        rays.clear();
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < o.width; ++x)
                for (int sy = 0; sy < s; ++sy)
                    for (int sx = 0; sx < s; ++sx) {
                        const float px = (float(x) + (float(sx) + 0.5f) / float(s)) / float(o.width);
                        const float py = (float(y) + (float(sy) + 0.5f) / float(s)) / float(o.height);
                        const float cx = (2.0f * px - 1.0f) * th * aspect, cy = (1.0f - 2.0f * py) * th;
                        rays.push_back({eye, 0.0f, glm::normalize(forward + cx * right + cy * up),
                                        std::numeric_limits<float>::infinity()});
                    }
        hits.resize(rays.size());
        backend->intersect(rays, hits);
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < o.width; ++x) {
                glm::vec3 sum(0.0f);
                const std::size_t first = std::size_t(y - y0) * row_rays + std::size_t(x) * std::size_t(s * s);
                for (std::size_t i = first; i < first + std::size_t(s * s); ++i) {
                    const RayHit& h = hits[i];
                    if (h.triangle == kNoHit) {
                        sum += sky ? sky(rays[i].direction) : background;
                        continue;
                    }
                    const std::uint32_t* tri = &mesh.indices[3 * std::size_t(h.triangle)];
                    sum += shade(tri, h.u, h.v, rays[i].direction);
                }
                sum /= float(s * s);
                float* p = img.pixel(x, y);
                p[0] = sum.x;
                p[1] = sum.y;
                p[2] = sum.z;
            }
    }
    return img;
}

Image render_ao_preview(const Mesh& mesh, const AoPreviewOptions& o) {
    validate_mesh(mesh, "mesh");
    const VertexAttribute* ao = mesh.find_attribute("ao");
    if (!ao || ao->components != 1)
        throw Error("the mesh has no baked 'ao' attribute to preview; bake it first", "mesh");
    return bake::render_preview(mesh, o, [&](const std::uint32_t* tri, float u, float v, const glm::vec3&) {
        const float a = (1.0f - u - v) * ao->values[tri[0]] + u * ao->values[tri[1]] + v * ao->values[tri[2]];
        return glm::vec3(srgb_to_linear(std::clamp(a, 0.0f, 1.0f)));
    });
}

Image render_vertex_preview(const Mesh& mesh, std::span<const glm::vec3> linear_rgb, const AoPreviewOptions& o) {
    validate_mesh(mesh, "mesh");
    if (linear_rgb.size() != mesh.vertex_count())
        throw Error(fmt::format("{} vertex colours for {} vertices", linear_rgb.size(), mesh.vertex_count()), "mesh");
    return bake::render_preview(mesh, o, [&](const std::uint32_t* tri, float u, float v, const glm::vec3&) {
        return (1.0f - u - v) * linear_rgb[tri[0]] + u * linear_rgb[tri[1]] + v * linear_rgb[tri[2]];
    });
}

Image render_texture_preview(const Mesh& mesh, const AoTexture& texture, int uv_set,
                             const std::vector<Image>& base_colors, const AoPreviewOptions& o) {
    validate_mesh(mesh, "mesh");
    if (uv_set < 0 || std::size_t(uv_set) >= mesh.texcoords.size())
        throw Error(fmt::format("the mesh has no UV set {} to read the texture with", uv_set), "uv_set");
    if (texture.ao.size() != std::size_t(texture.texture_size) * std::size_t(texture.texture_size))
        throw Error("the AO texture is empty; bake it first", "texture");
    const std::vector<glm::vec2>& uvs = mesh.texcoords[std::size_t(uv_set)];
    return bake::render_preview(mesh, o, [&](const std::uint32_t* tri, float u, float v, const glm::vec3&) {
        const auto triangle = std::size_t(tri - mesh.indices.data()) / 3;
        const glm::vec2 uv = (1.0f - u - v) * uvs[tri[0]] + u * uvs[tri[1]] + v * uvs[tri[2]];
        glm::vec3 albedo(0.8f);
        if (!mesh.triangle_parts.empty()) {
            const int m = mesh.parts[mesh.triangle_parts[triangle]].material;
            if (m >= 0) {
                const MeshMaterial& mat = mesh.materials[std::size_t(m)];
                albedo = glm::vec3(mat.base_color);
                if (std::size_t(m) < base_colors.size() && base_colors[std::size_t(m)].width > 0) {
                    // Nearest texel of the base colour image (its own UV set is assumed to be uv_set's).
                    const Image& img = base_colors[std::size_t(m)];
                    const float fu = uv.x - std::floor(uv.x), fv = uv.y - std::floor(uv.y);
                    const int x = std::clamp(int(fu * float(img.width)), 0, img.width - 1);
                    const int y = std::clamp(int(fv * float(img.height)), 0, img.height - 1);
                    const float* p = img.pixel(x, y);
                    albedo *= glm::vec3(p[0], p[1], p[2]);
                }
            }
        }
        return albedo * std::clamp(sample_texture(texture, uv), 0.0f, 1.0f);
    });
}

} // namespace skybake
