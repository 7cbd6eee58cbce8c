// The sky as an image-based light for other engines: EXT_lights_image_based
// (Khronos glTF repository, extensions/2.0/Vendor/EXT_lights_image_based),
// the format Babylon.js's glTF loader reads: order-2 irradiance SH and an
// RGBD cube map. See skybake/prt.h for the conventions.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/image_io.h"
#include "skybake/prt.h"

namespace skybake {

std::array<double, 9> babylon_sh_basis(const glm::dvec3& d) {
    const double pi = M_PI;
    const double c0 = std::sqrt(1.0 / (4.0 * pi)), c1 = std::sqrt(3.0 / (4.0 * pi)), c2 = std::sqrt(15.0 / (4.0 * pi)),
                 c20 = std::sqrt(5.0 / (16.0 * pi)), c22 = std::sqrt(15.0 / (16.0 * pi));
    return {c0,
            -c1 * d.y,
            c1 * d.z,
            -c1 * d.x,
            c2 * d.x * d.y,
            -c2 * d.y * d.z,
            c20 * (3.0 * d.z * d.z - 1.0),
            -c2 * d.x * d.z,
            c22 * (d.x * d.x - d.y * d.y)};
}

glm::dvec3 cube_face_direction(int face, int i, int j, int n) {
    const double s = 2.0 * (double(i) + 0.5) / double(n) - 1.0, t = 2.0 * (double(j) + 0.5) / double(n) - 1.0;
    glm::dvec3 d;
    switch (face) {
    case 0: d = {1.0, -t, -s}; break;
    case 1: d = {-1.0, -t, s}; break;
    case 2: d = {s, 1.0, t}; break;
    case 3: d = {s, -1.0, -t}; break;
    case 4: d = {s, -t, 1.0}; break;
    default: d = {-s, -t, -1.0}; break;
    }
    return d / std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

ImageBasedLight sky_image_based_light(const SkySource& sky, const SkyLightSettings& settings, const SphereRule& rule,
                                      int face_size) {
    const int n = face_size;
    if (n < 1 || n > 1024 || (n & (n - 1)) != 0)
        throw Error(fmt::format("face size {} is not a power of two from 1 to 1024", n), "face_size");
    ImageBasedLight out;
    out.face_size = n;

    // Irradiance: the order-2 light in skybake's basis, carried into
    // Babylon.js's by projection with a rule exact for the product of two
    // order-2 functions (degree 4), then convolved with the cosine lobe.
    const ShLight light = sky_light(sky, settings, 2, rule);
    const SphereRule exact = parse_rule("lebedev:26");
    const double cosine[9] = {M_PI, 2.0 * M_PI / 3.0, 2.0 * M_PI / 3.0, 2.0 * M_PI / 3.0, M_PI / 4.0,
                              M_PI / 4.0, M_PI / 4.0, M_PI / 4.0, M_PI / 4.0};
    std::array<glm::dvec3, 9> c{};
    std::vector<double> y(9);
    for (std::size_t k = 0; k < exact.size(); ++k) {
        const glm::dvec3 x = exact.points[k];
        sh_eval(2, x, y.data());
        glm::dvec3 f(0.0);
        for (int i = 0; i < 9; ++i)
            f += glm::dvec3(light.coeffs[std::size_t(i)]) * y[std::size_t(i)];
        const std::array<double, 9> b = babylon_sh_basis(x);
        for (int i = 0; i < 9; ++i)
            c[std::size_t(i)] += 4.0 * M_PI * exact.weights[k] * f * b[std::size_t(i)];
    }
    for (int i = 0; i < 9; ++i)
        out.irradiance[std::size_t(i)] = glm::vec3(cosine[i] * c[std::size_t(i)]);

    // Faces: the radiance at each texel centre, as sky_light() samples it.
    const glm::vec3 sun = sun_direction(settings.sun_elevation_deg, settings.sun_azimuth_deg);
    const float density = float(std::clamp(sky.atmosphere().density_from_altitude(settings.altitude_km), 1e-30, 1.0));
    const std::size_t texels = std::size_t(n) * std::size_t(n);
    std::vector<SkySample> samples(texels);
    std::vector<glm::vec3> radiance(texels);
    std::vector<std::uint8_t> rgbd(4 * texels);
    for (int face = 0; face < 6; ++face) {
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const glm::vec3 d(cube_face_direction(face, i, j, n));
                samples[std::size_t(j) * std::size_t(n) + std::size_t(i)] = {
                    std::clamp(d.y, -1.0f, 1.0f), std::clamp(glm::dot(d, sun), -1.0f, 1.0f),
                    std::clamp(sun.y, -1.0f, 1.0f), density};
            }
        sky.evaluate(samples, radiance);
        for (std::size_t p = 0; p < texels; ++p) {
            const glm::vec3 v = glm::max(radiance[p], glm::vec3(0.0f));
            const float m = std::max({v.x, v.y, v.z, 1e-7f});
            const float D = std::clamp(std::floor(std::max(255.0f / m, 1.0f)) / 255.0f, 0.0f, 1.0f);
            for (int ch = 0; ch < 3; ++ch)
                rgbd[4 * p + std::size_t(ch)] = std::uint8_t(
                    std::lround(255.0f * std::clamp(std::pow(v[ch] * D, 1.0f / 2.2f), 0.0f, 1.0f)));
            rgbd[4 * p + 3] = std::uint8_t(std::lround(255.0f * D));
        }
        out.faces[std::size_t(face)] = encode_png8(n, n, 4, rgbd);
    }
    return out;
}

} // namespace skybake
