// The per-vertex albedo of a mesh, from its materials, images and colours.
#include <algorithm>
#include <cmath>
#include <system_error>

#include <glm/common.hpp>

#include "skybake/error.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/prt.h"

namespace skybake {

namespace {

// Bilinear, repeating, texel centres at (i + 0.5) / size; uv in glTF's
// convention (v down from the image's top row).
glm::vec3 sample_bilinear(const Image& img, glm::vec2 uv) {
    const float x = uv.x * float(img.width) - 0.5f, y = uv.y * float(img.height) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    const auto wrap = [](float i, int n) {
        const long k = long(i) % long(n);
        return int(k < 0 ? k + n : k);
    };
    const int x0 = wrap(fx, img.width), x1 = wrap(fx + 1.0f, img.width);
    const int y0 = wrap(fy, img.height), y1 = wrap(fy + 1.0f, img.height);
    const auto at = [&](int px, int py) {
        const float* p = img.pixel(px, py);
        return glm::vec3(p[0], p[1], p[2]);
    };
    return glm::mix(glm::mix(at(x0, y0), at(x1, y0), tx), glm::mix(at(x0, y1), at(x1, y1), tx), ty);
}

} // namespace

std::vector<int> vertex_materials(const Mesh& mesh) {
    std::vector<int> material(mesh.vertex_count(), -1);
    if (mesh.triangle_parts.size() != mesh.triangle_count())
        return material;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t part = mesh.triangle_parts[t];
        const int m = part < mesh.parts.size() ? mesh.parts[part].material : -1;
        if (m < 0 || std::size_t(m) >= mesh.materials.size())
            continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = mesh.indices[3 * t + std::size_t(k)];
            if (material[v] < 0)
                material[v] = m;
        }
    }
    return material;
}

bool surface_base_color(const Mesh& mesh, const std::vector<Image>& images, std::uint32_t triangle, float u, float v,
                        glm::vec3& out) {
    if (triangle >= mesh.triangle_count() || mesh.triangle_parts.size() != mesh.triangle_count())
        return false;
    const std::uint32_t part = mesh.triangle_parts[triangle];
    const int m = part < mesh.parts.size() ? mesh.parts[part].material : -1;
    if (m < 0 || std::size_t(m) >= mesh.materials.size() || std::size_t(m) >= images.size())
        return false;
    const Image& img = images[std::size_t(m)];
    const MeshMaterial& mm = mesh.materials[std::size_t(m)];
    const auto set = std::size_t(std::max(mm.base_color_texcoord, 0));
    const std::size_t n = mesh.vertex_count();
    if (img.width <= 0 || img.height <= 0 || set >= mesh.texcoords.size() || mesh.texcoords[set].size() != n)
        return false;
    const std::uint32_t* t = &mesh.indices[3 * std::size_t(triangle)];
    const float w[3] = {1.0f - u - v, u, v};
    glm::vec2 uv(0.0f);
    glm::vec3 colour(0.0f);
    for (int k = 0; k < 3; ++k) {
        uv += w[k] * mesh.texcoords[set][t[k]];
        colour += w[k] * (mesh.colors.size() == n ? glm::vec3(mesh.colors[t[k]]) : glm::vec3(1.0f));
    }
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y) || std::abs(uv.x) >= 1e6f || std::abs(uv.y) >= 1e6f)
        return false;
    out = glm::clamp(glm::vec3(mm.base_color) * sample_bilinear(img, uv) * colour, glm::vec3(0.0f), glm::vec3(1.0f));
    return true;
}

std::vector<Image> base_color_images(const Mesh& mesh) {
    std::vector<Image> images(mesh.materials.size());
    for (std::size_t m = 0; m < mesh.materials.size(); ++m) {
        const MeshMaterial& mm = mesh.materials[m];
        const std::string& file = mm.base_color_texture;
        std::error_code ec;
        try {
            if (!mm.base_color_image.empty())
                images[m] = load_image_from_memory(mm.base_color_image.data(), mm.base_color_image.size(),
                                                   mm.base_color_image_type == "image/jpeg" ? "jpg" : "png",
                                                   mm.name.empty() ? "embedded image" : mm.name);
            else if (!file.empty() && std::filesystem::is_regular_file(file, ec))
                images[m] = load_image(file);
        } catch (const Error&) {
            images[m] = Image(); // left out, as a missing file
        }
    }
    return images;
}

std::vector<glm::vec3> mesh_albedo(const Mesh& mesh, const glm::vec3& fallback, bool sample_images) {
    return mesh_albedo(mesh, sample_images ? base_color_images(mesh) : std::vector<Image>(), fallback);
}

std::vector<glm::vec3> mesh_albedo(const Mesh& mesh, const std::vector<Image>& decoded, const glm::vec3& fallback) {
    const std::size_t n = mesh.vertex_count();
    const bool colors = mesh.colors.size() == n;
    std::vector<glm::vec3> albedo(n, fallback);
    if (colors)
        for (std::size_t v = 0; v < n; ++v)
            albedo[v] = glm::vec3(mesh.colors[v]);
    if (mesh.materials.empty() || mesh.triangle_parts.size() != mesh.triangle_count())
        return albedo;
    const std::vector<int> material = vertex_materials(mesh);
    const Image none;
    for (std::size_t v = 0; v < n; ++v) {
        if (material[v] < 0)
            continue;
        const MeshMaterial& mm = mesh.materials[std::size_t(material[v])];
        glm::vec3 a = glm::vec3(mm.base_color);
        const std::size_t m = std::size_t(material[v]);
        const Image& img = m < decoded.size() ? decoded[m] : none;
        const auto set = std::size_t(std::max(mm.base_color_texcoord, 0));
        if (img.width > 0 && img.height > 0 && set < mesh.texcoords.size() && mesh.texcoords[set].size() == n &&
            std::isfinite(mesh.texcoords[set][v].x) && std::isfinite(mesh.texcoords[set][v].y) &&
            std::abs(mesh.texcoords[set][v].x) < 1e6f && std::abs(mesh.texcoords[set][v].y) < 1e6f)
            a *= sample_bilinear(img, mesh.texcoords[set][v]);
        if (colors)
            a *= glm::vec3(mesh.colors[v]);
        albedo[v] = glm::clamp(a, glm::vec3(0.0f), glm::vec3(1.0f));
    }
    return albedo;
}

} // namespace skybake
