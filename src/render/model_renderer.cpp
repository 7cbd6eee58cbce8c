// The model viewer's renderer: relighting of precomputed radiance transfer
// (Sloan, Kautz & Snyder 2002) on OpenGL, one dot product per vertex with the
// GLSL of export_prt_glsl(), under the sky network of seed 000 per pixel. The
// C++ twin is relight() with render_prt_preview() (skybake/prt.h), on the
// same camera (preview_camera()). The sun's shadow map is Williams 1978
// ("Casting curved shadows on curved surfaces"), filtered by
// percentage-closer filtering (Reeves, Salesin & Cook 1987); the glossy
// layer is DPRT (Svistunov, seed 002) prefiltered into an equirectangular
// map of the mirror direction, texel by texel with dprt_glossy().
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include "gl/gl.h"
#include "render/shaders.h"
#include "skybake/error.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "skybake/viewer.h"

namespace skybake {

using namespace skybake::gl;

namespace {

constexpr const char* kVersion = "#version 330 core\n";
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// T_lm = (Â_l / π) Y_lm(n) per vertex, grey.
std::vector<float> unshadowed_transfer(const std::vector<glm::vec3>& normals, int order) {
    const int nc = sh_count(order);
    std::vector<double> zonal(std::size_t(order + 1));
    for (int l = 0; l <= order; ++l)
        zonal[std::size_t(l)] = clamped_cosine_zonal(l) / M_PI;
    std::vector<float> out(normals.size() * std::size_t(nc));
    std::vector<double> y(static_cast<std::size_t>(nc));
    for (std::size_t v = 0; v < normals.size(); ++v) {
        sh_eval(order, glm::dvec3(normals[v]), y.data());
        for (int l = 0; l <= order; ++l)
            for (int m = -l; m <= l; ++m) {
                const int i = sh_index(l, m);
                out[v * std::size_t(nc) + std::size_t(i)] = float(zonal[std::size_t(l)] * y[std::size_t(i)]);
            }
    }
    return out;
}


// The equirectangular layout of the viewer's maps (the GLSL sb_equirect_uv()
// of model_stages.glsl): texel (i, j) of a width × height map, row 0 at the
// zenith, holds the direction at φ = 2π ((i + ½)/width − ½) from +z towards
// +x and θ = π (j + ½)/height from +y.
glm::vec3 equirect_direction(int i, int j, int width, int height) {
    const double phi = 2.0 * M_PI * ((double(i) + 0.5) / double(width) - 0.5);
    const double theta = M_PI * (double(j) + 0.5) / double(height);
    return glm::vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                     float(std::sin(theta) * std::cos(phi)));
}

// An RGB float texture of width × height texels (rows in order), linear filtering, wrapping in u.
void upload_equirect(Texture& tex, const std::vector<glm::vec3>& texels, int width, int height) {
    if (!tex)
        tex = make_texture();
    glBindTexture(GL_TEXTURE_2D, tex.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, width, height, 0, GL_RGB, GL_FLOAT, texels.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
}

constexpr int kSkyMapWidth = 256, kSkyMapHeight = 256;  // the reference sky's background: ψ × θ, 0.7° texels
constexpr int kGlossyMapWidth = 128, kGlossyMapHeight = 64; // the prefiltered glossy layer
constexpr int kShadowMapSize = 2048;

} // namespace

const char* model_shading_name(ModelShading s) {
    switch (s) {
    case ModelShading::Prt: return "prt";
    case ModelShading::Ao: return "ao";
    case ModelShading::A: return "a";
    case ModelShading::Unshadowed: return "unshadowed";
    case ModelShading::Dprt: return "dprt";
    case ModelShading::Visibility: return "visibility";
    }
    return "?";
}

ModelShading parse_model_shading(const std::string& text) {
    for (ModelShading s : {ModelShading::Prt, ModelShading::Ao, ModelShading::A, ModelShading::Unshadowed,
                           ModelShading::Dprt, ModelShading::Visibility})
        if (text == model_shading_name(s))
            return s;
    throw Error(fmt::format("unknown shading '{}'; use prt, ao, a, unshadowed, dprt or visibility", text), "shading");
}

const char* sun_shadow_name(SunShadow s) {
    switch (s) {
    case SunShadow::Map: return "map";
    case SunShadow::Vertex: return "vertex";
    case SunShadow::None: return "none";
    }
    return "?";
}

SunShadow parse_sun_shadow(const std::string& text) {
    for (SunShadow s : {SunShadow::Map, SunShadow::Vertex, SunShadow::None})
        if (text == sun_shadow_name(s))
            return s;
    throw Error(fmt::format("unknown shadow '{}'; use map, vertex or none", text), "shadow");
}

float model_auto_exposure_ev(const Image& img) {
    std::vector<float> lum;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            if (const float l = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; l > 0.0f && std::isfinite(l))
                lum.push_back(l);
        }
    if (lum.empty())
        return 0.0f;
    const auto k = std::ptrdiff_t(0.95 * double(lum.size() - 1));
    std::nth_element(lum.begin(), lum.begin() + k, lum.end());
    return std::log2(0.6f / lum[std::size_t(k)]);
}

ViewerModel load_viewer_model(const std::filesystem::path& path) {
    ViewerModel m;
    std::error_code ec;
    if (std::filesystem::exists(prt_sidecar_path(path), ec)) {
        PrtModel p = load_prt(path);
        m.mesh = std::move(p.mesh);
        m.transfer = std::move(p.transfer);
        m.albedo = std::move(p.albedo);
    } else {
        ImportReport report;
        m.mesh = load_mesh(path, &report);
        m.albedo = mesh_albedo(m.mesh);
        m.normals_computed = !report.normals_present;
    }
    if (m.mesh.normals.size() != m.mesh.vertex_count()) {
        compute_normals(m.mesh);
        m.normals_computed = true;
    }
    return m;
}

struct ModelRenderer::Impl {
    std::unique_ptr<GlContext> own_context; // headless; null in the caller's context
    const SkySource* sky = nullptr;
    const ViewerModel* model = nullptr;
    SkyProjector projector;
    SphereRule light_rule;
    std::unique_ptr<RayQueries> queries;
    int light_order = 3, transfer_order = 3, attributes = 4;
    Program model_program, background_program, map_background_program, flat_program, depth_program;
    Buffer weights, positions, normals, albedo, vertex_extra, transfer, indices;
    VertexArray vao, empty_vao;
    std::unique_ptr<RenderTarget> target;
    ShLight light;
    bool have_light = false;
    SkyLightSettings light_settings;
    // Per-vertex (visibility, A, u, v): visibility of the sun (shadow=vertex)
    // or of one rule direction, the shading coefficient, and the UV of the
    // vertex's base colour image.
    std::vector<float> extra;
    // The base colour images, sampled per pixel: one texture per material
    // (white where a material has none), the triangles sorted by material
    // into runs of the index buffer. Off once set_albedo() replaces the albedo.
    struct Run {
        int material = -1;
        std::size_t first = 0, count = 0; // indices
    };
    std::vector<Run> runs;
    std::vector<Texture> base_color;
    Texture white;
    bool textured = false;
    glm::vec3 visibility_for{0.0f};
    bool have_visibility = false;
    ModelShading uploaded_shading = ModelShading::Prt;
    bool have_shading = false;
    // The reference sky's background map, the glossy map and the shadow map.
    Texture sky_map, glossy_map, shadow_depth;
    Framebuffer shadow_fbo;
    bool have_sky_map = false, have_glossy = false, have_shadow = false;
    SkyLightSettings sky_map_settings;
    double glossy_exponent = 0.0;
    glm::vec3 shadow_for{0.0f};
    glm::mat4 shadow_from_world{1.0f};
    float shadow_texel_world = 0.0f;
    PreviewCamera base_camera;
    int last_w = 0, last_h = 0;

    Impl(const ViewerModel& m, const SkySource& s, const SphereRule& rule, int order)
        : sky(&s), model(&m), projector(order, rule), light_rule(rule), light_order(order) {}

    void make_current() {
        if (own_context)
            own_context->make_current();
    }

    ModelShading effective(ModelShading s) const {
        if (!model->has_transfer())
            return s == ModelShading::Visibility ? s : ModelShading::Unshadowed;
        if (s == ModelShading::A && model->transfer.shading.size() != model->mesh.vertex_count())
            return ModelShading::Ao;
        return s;
    }

    // The per-vertex vec4 attributes of one shading mode: channels × coefficients, zero-padded.
    void upload_transfer(ModelShading s) {
        const std::size_t n = model->mesh.vertex_count();
        const int nc = sh_count(transfer_order);
        const int per_vertex = attributes * 4;
        std::vector<float> data(n * std::size_t(per_vertex), 0.0f);
        if (s == ModelShading::Prt || s == ModelShading::Dprt) {
            const Transfer& t = model->transfer;
            const int count = t.channels * t.coefficients;
            for (std::size_t v = 0; v < n; ++v)
                std::copy_n(t.vertex(v), count, &data[v * std::size_t(per_vertex)]);
        } else {
            const std::vector<float> u = unshadowed_transfer(model->mesh.normals, transfer_order);
            const Transfer& t = model->transfer;
            const float k = float(2.0 * std::sqrt(M_PI));
            for (std::size_t v = 0; v < n; ++v) {
                float scale = 1.0f;
                if (s == ModelShading::Ao)
                    scale = std::clamp(k * t.vertex(v)[0], 0.0f, 1.0f);
                else if (s == ModelShading::A)
                    scale = t.shading[v];
                for (int i = 0; i < nc; ++i)
                    data[v * std::size_t(per_vertex) + std::size_t(i)] =
                        scale * u[v * std::size_t(nc) + std::size_t(i)];
            }
        }
        glBindBuffer(GL_ARRAY_BUFFER, transfer.get());
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
        uploaded_shading = s;
        have_shading = true;
    }

    void upload_extra() {
        glBindBuffer(GL_ARRAY_BUFFER, vertex_extra.get());
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(extra.size() * sizeof(float)), extra.data(), GL_DYNAMIC_DRAW);
    }

    // Per-vertex visibility in `direction` (one ray per vertex), when it changed.
    void update_visibility(const glm::vec3& direction, ModelFrameStats* stats) {
        if (have_visibility && direction == visibility_for)
            return;
        const auto t0 = Clock::now();
        const std::vector<float> v = sun_visibility(model->mesh, direction, *queries);
        for (std::size_t i = 0; i < v.size(); ++i)
            extra[4 * i] = v[i];
        upload_extra();
        visibility_for = direction;
        have_visibility = true;
        if (stats)
            stats->sun_seconds += seconds_since(t0);
    }

    void update_light(const ModelViewSettings& st, ModelFrameStats* stats) {
        SkyLightSettings ls;
        ls.sun_elevation_deg = st.sun_elevation_deg;
        ls.sun_azimuth_deg = st.sun_azimuth_deg;
        ls.altitude_km = st.altitude_km;
        ls.sun = st.sun;
        if (!have_light || ls.sun_elevation_deg != light_settings.sun_elevation_deg ||
            ls.sun_azimuth_deg != light_settings.sun_azimuth_deg || ls.altitude_km != light_settings.altitude_km ||
            ls.sun != light_settings.sun) {
            const auto t0 = Clock::now();
            light = projector.project(*sky, ls);
            light_settings = ls;
            have_light = true;
            have_glossy = false;
            if (stats)
                stats->light_seconds = seconds_since(t0);
        }
    }

    // The reference sky seen from the observer, per texel of the background map. The sky depends
    // on the view's azimuth only relative to the sun's, so the map is indexed by that relative
    // azimuth ψ ∈ [0, π] (it is symmetric about the sun's vertical plane) and the zenith angle
    // θ ∈ [0, π]: texel (i, j) holds ψ = π (i + ½)/width, θ = π (j + ½)/height, and the map is
    // computed again when the sun's elevation or the altitude changes, not its azimuth.
    void update_sky_map(ModelFrameStats* stats) {
        if (have_sky_map && light_settings.sun_elevation_deg == sky_map_settings.sun_elevation_deg &&
            light_settings.altitude_km == sky_map_settings.altitude_km)
            return;
        const auto t0 = Clock::now();
        const glm::vec3 s = sun_direction(light_settings.sun_elevation_deg, 0.0);
        const float density =
            float(std::clamp(sky->atmosphere().density_from_altitude(light_settings.altitude_km), 1e-30, 1.0));
        std::vector<SkySample> samples(std::size_t(kSkyMapWidth) * kSkyMapHeight);
        for (int j = 0; j < kSkyMapHeight; ++j)
            for (int i = 0; i < kSkyMapWidth; ++i) {
                const double psi = M_PI * (double(i) + 0.5) / double(kSkyMapWidth);
                const double theta = M_PI * (double(j) + 0.5) / double(kSkyMapHeight);
                // The direction at relative azimuth ψ from the sun's (which is towards +z here).
                const glm::vec3 d(float(std::sin(theta) * std::sin(psi)), float(std::cos(theta)),
                                  float(std::sin(theta) * std::cos(psi)));
                SkySample& q = samples[std::size_t(j) * kSkyMapWidth + std::size_t(i)];
                q.cos_view_zenith = std::clamp(d.y, -1.0f, 1.0f);
                q.cos_view_sun = std::clamp(glm::dot(d, s), -1.0f, 1.0f);
                q.cos_sun_zenith = std::clamp(s.y, -1.0f, 1.0f);
                q.density = density;
            }
        std::vector<glm::vec3> radiance(samples.size());
        sky->evaluate(samples, radiance);
        for (glm::vec3& r : radiance)
            r = glm::max(r, glm::vec3(0.0f));
        upload_equirect(sky_map, radiance, kSkyMapWidth, kSkyMapHeight);
        glBindTexture(GL_TEXTURE_2D, sky_map.get());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glBindTexture(GL_TEXTURE_2D, 0);
        sky_map_settings = light_settings;
        have_sky_map = true;
        if (stats)
            stats->background_seconds = seconds_since(t0);
    }

    // G(r) = Σ_k λ_k max(L(g_r x_k), 0) per texel (dprt_glossy() with n = v = r, so that the mirror
    // direction is r), the Phong rule of render_prt_preview(): phong:a=exponent,n=order/2+1.
    void update_glossy(double exponent) {
        if (have_glossy && exponent == glossy_exponent)
            return;
        const SphereRule rule = phong_rule(exponent, light.order / 2 + 1);
        std::vector<glm::dvec3> c(light.coeffs.begin(), light.coeffs.end());
        std::vector<glm::vec3> texels(std::size_t(kGlossyMapWidth) * kGlossyMapHeight);
        for (int j = 0; j < kGlossyMapHeight; ++j)
            for (int i = 0; i < kGlossyMapWidth; ++i) {
                const glm::vec3 r = equirect_direction(i, j, kGlossyMapWidth, kGlossyMapHeight);
                texels[std::size_t(j) * kGlossyMapWidth + std::size_t(i)] = dprt_glossy(
                    rule,
                    [&](const glm::vec3& x) {
                        return glm::max(glm::vec3(sh_evaluate(c, light.order, glm::dvec3(x))), 0.0f);
                    },
                    r, r);
            }
        upload_equirect(glossy_map, texels, kGlossyMapWidth, kGlossyMapHeight);
        glossy_exponent = exponent;
        have_glossy = true;
    }

    // Depth of the mesh seen from the sun, orthographic over the bounding sphere.
    void update_shadow_map(ModelFrameStats* stats) {
        const glm::vec3 s = light.sun_direction;
        if (have_shadow && s == shadow_for)
            return;
        const auto t0 = Clock::now();
        if (!shadow_depth) {
            shadow_depth = make_texture();
            glBindTexture(GL_TEXTURE_2D, shadow_depth.get());
            glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, kShadowMapSize, kShadowMapSize, 0,
                         GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
            const float border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
            glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
            GLuint fbo = 0;
            glGenFramebuffers(1, &fbo);
            shadow_fbo = Framebuffer(fbo);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_depth.get(), 0);
            glDrawBuffer(GL_NONE);
            glReadBuffer(GL_NONE);
            if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
                throw Error("the shadow map's framebuffer is incomplete on this driver", "OpenGL");
        }
        const glm::vec3 c = base_camera.centre;
        const float r = base_camera.radius;
        glm::vec3 up_hint(0.0f, 1.0f, 0.0f);
        if (std::abs(s.y) > 0.999f)
            up_hint = glm::vec3(0.0f, 0.0f, 1.0f);
        const glm::mat4 view = glm::lookAt(c + 2.0f * r * s, c, up_hint);
        const glm::mat4 proj = glm::ortho(-r, r, -r, r, 0.5f * r, 3.5f * r);
        const glm::mat4 clip = proj * view;
        glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo.get());
        glViewport(0, 0, kShadowMapSize, kShadowMapSize);
        glClearDepth(1.0);
        glClear(GL_DEPTH_BUFFER_BIT);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDisable(GL_CULL_FACE);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1.5f, 2.0f);
        glUseProgram(depth_program.get());
        glUniformMatrix4fv(glGetUniformLocation(depth_program.get(), "u_clip_from_world"), 1, GL_FALSE,
                           glm::value_ptr(clip));
        glBindVertexArray(vao.get());
        glDrawElements(GL_TRIANGLES, GLsizei(model->mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
        glBindVertexArray(0);
        glDisable(GL_POLYGON_OFFSET_FILL);
        const glm::mat4 bias = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f)) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
        shadow_from_world = bias * clip;
        shadow_texel_world = 2.0f * r / float(kShadowMapSize);
        shadow_for = s;
        have_shadow = true;
        if (stats)
            stats->sun_seconds += seconds_since(t0);
    }

    void ensure_target(int w, int h) {
        if (!target || target->width() != w || target->height() != h)
            target = std::make_unique<RenderTarget>(w, h);
    }

    PreviewCamera camera(const ModelViewSettings& st) const {
        PreviewCamera c = preview_camera(model->mesh, st.camera);
        c.eye = c.centre + (c.eye - c.centre) * st.zoom;
        return c;
    }

    glm::mat4 clip_from_world(const PreviewCamera& c) const {
        const float dist = glm::length(c.eye - c.centre);
        const float near = std::max(dist - 1.5f * c.radius, 1e-3f * dist);
        const float far = dist + 1.5f * c.radius;
        const glm::mat4 view = glm::lookAt(c.eye, c.eye + c.forward, c.up);
        const glm::mat4 proj = glm::perspective(2.0f * std::atan(c.tan_half_fov_y), c.aspect, near, far);
        return proj * view;
    }

    // One frame of w × h pixels into the target (left bound).
    void draw_frame(const ModelViewSettings& st, int w, int h, ModelFrameStats* stats);

    // Averages samples × samples blocks of the supersampled target.
    static Image downsample(const Image& big, int samples) {
        if (samples == 1)
            return big;
        const int w = big.width / samples, h = big.height / samples;
        Image out(w, h);
        const float k = 1.0f / float(samples * samples);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float sum[3] = {0.0f, 0.0f, 0.0f};
                for (int sy = 0; sy < samples; ++sy)
                    for (int sx = 0; sx < samples; ++sx) {
                        const float* p = big.pixel(x * samples + sx, y * samples + sy);
                        for (int c = 0; c < 3; ++c)
                            sum[c] += p[c];
                    }
                float* q = out.pixel(x, y);
                for (int c = 0; c < 3; ++c)
                    q[c] = sum[c] * k;
            }
        return out;
    }
};

namespace {

std::unique_ptr<ModelRenderer::Impl> make_impl(const ViewerModel& model, const SkySource& sky,
                                               const SphereRule& light_rule, int light_order, bool headless) {
    validate_mesh(model.mesh, "mesh");
    if (model.mesh.normals.size() != model.mesh.vertex_count())
        throw Error("the model has no normals; load it with load_viewer_model()", "mesh");
    if (model.albedo.size() != model.mesh.vertex_count())
        throw Error(fmt::format("{} albedo values for {} vertices", model.albedo.size(), model.mesh.vertex_count()),
                    "albedo");
    const int transfer_order = model.has_transfer() ? model.transfer.order : light_order;
    if (light_order < transfer_order || light_order > kPrtMaxOrder)
        throw Error(fmt::format("the light's SH order must be {} to {} (the transfer's order or more); got {}",
                                transfer_order, kPrtMaxOrder, light_order),
                    "order");
    auto impl = std::make_unique<ModelRenderer::Impl>(model, sky, light_rule, light_order);
    ModelRenderer::Impl& m = *impl;
    m.transfer_order = transfer_order;
    const int channels = model.has_transfer() ? model.transfer.channels : 1;
    m.attributes = (channels * sh_count(transfer_order) + 3) / 4;
    if (headless) {
        m.own_context = create_headless_context();
        m.own_context->make_current();
    }
    GLint max_attribs = 0;
    glGetIntegerv(GL_MAX_VERTEX_ATTRIBS, &max_attribs);
    if (4 + m.attributes > max_attribs)
        throw Error(fmt::format("a transfer of order {} ({} channel{}) needs {} vertex attributes; this driver has {}",
                                transfer_order, channels, channels == 1 ? "" : "s", 4 + m.attributes, max_attribs),
                    "order");
    m.queries = make_ray_queries("embree");
    m.queries->set_mesh(model.mesh);
    AoPreviewOptions framing;
    m.base_camera = preview_camera(model.mesh, framing);

    const std::string defines = fmt::format("#define SKYBAKE_PRT_ATTRIBUTES {}\n#define SKYBAKE_SH_COUNT {}\n",
                                            m.attributes, sh_count(light_order));
    // The light array of the export has the transfer's size; the uniform has the light's.
    std::string prt = export_prt_glsl(transfer_order, channels);
    if (light_order != transfer_order) {
        const std::string from = fmt::format("vec3 light[{}]", sh_count(transfer_order));
        prt.replace(prt.find(from), from.size(), fmt::format("vec3 light[{}]", sh_count(light_order)));
    }
    auto stage = [&](const std::string& body, const char* name) {
        ShaderSource s;
        s.pieces = {kVersion,      defines, fmt::format("#define {}\n", name), render::shaders::shared_source,
                    render::shaders::tone_curve, body, render::shaders::model_stages, render::shaders::screen_stages};
        return s;
    };
    m.model_program = link_program("model", stage(prt, "SKYBAKE_STAGE_MODEL_VS"), stage("", "SKYBAKE_STAGE_MODEL_FS"));
    m.flat_program = link_program("flat", stage("", "SKYBAKE_STAGE_FLAT_VS"), stage("", "SKYBAKE_STAGE_FLAT_FS"));
    m.depth_program = link_program("depth", stage("", "SKYBAKE_STAGE_FLAT_VS"), stage("", "SKYBAKE_STAGE_DEPTH_FS"));
    if (sky.is_network()) {
        ShaderExportOptions eo;
        eo.uniform_block = true;
        const std::string network = export_neural_sky(sky.network_weights(), ExportLanguage::Glsl, eo);
        const std::vector<float> data = neural_sky_uniform_data(sky.network_weights());
        GLint max_block = 0;
        glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &max_block);
        if (GLint(data.size() * sizeof(float)) > max_block)
            throw Error(fmt::format("the network's weights need a {}-byte uniform block; this driver allows {}",
                                    data.size() * sizeof(float), max_block),
                        "OpenGL");
        m.weights = make_buffer();
        glBindBuffer(GL_UNIFORM_BUFFER, m.weights.get());
        glBufferData(GL_UNIFORM_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
        m.background_program = link_program("background", stage("", "SKYBAKE_STAGE_FULL_SCREEN_VS"),
                                            stage(network, "SKYBAKE_STAGE_BACKGROUND_FS"));
        const GLuint block = glGetUniformBlockIndex(m.background_program.get(), "SkybakeSkyWeights");
        if (block != GL_INVALID_INDEX)
            glUniformBlockBinding(m.background_program.get(), block, 0);
    } else {
        m.map_background_program = link_program("background", stage("", "SKYBAKE_STAGE_FULL_SCREEN_VS"),
                                                stage("", "SKYBAKE_STAGE_BACKGROUND_MAP_FS"));
    }

    const Mesh& mesh = model.mesh;
    const std::size_t n = mesh.vertex_count();
    auto upload = [](Buffer& b, GLenum target, const void* data, std::size_t bytes) {
        b = make_buffer();
        glBindBuffer(target, b.get());
        glBufferData(target, GLsizeiptr(bytes), data, GL_STATIC_DRAW);
    };
    m.vao = make_vertex_array();
    m.empty_vao = make_vertex_array();
    glBindVertexArray(m.vao.get());
    upload(m.positions, GL_ARRAY_BUFFER, mesh.positions.data(), n * sizeof(glm::vec3));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    upload(m.normals, GL_ARRAY_BUFFER, mesh.normals.data(), n * sizeof(glm::vec3));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    // The base colour images are sampled per pixel when the model's albedo is
    // mesh_albedo()'s (the default): the vertices then carry the rest of it.
    std::vector<Image> images;
    std::vector<glm::vec3> vertex_albedo = model.albedo;
    if (!mesh.materials.empty() && mesh.triangle_parts.size() == mesh.triangle_count()) {
        images = base_color_images(mesh);
        const bool any = std::any_of(images.begin(), images.end(), [](const Image& i) { return i.width > 0; });
        if (any && mesh_albedo(mesh, images) == model.albedo) {
            m.textured = true;
            vertex_albedo = mesh_albedo(mesh, glm::vec3(0.8f), false);
        } else {
            images.clear();
        }
    }
    upload(m.albedo, GL_ARRAY_BUFFER, vertex_albedo.data(), n * sizeof(glm::vec3));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    // (visibility, A, u, v) per vertex; A = 1 when the transfer has no shading coefficient.
    m.extra.assign(4 * n, 0.0f);
    const bool have_a = model.transfer.shading.size() == n;
    for (std::size_t v = 0; v < n; ++v)
        m.extra[4 * v + 1] = have_a ? model.transfer.shading[v] : 1.0f;
    const std::vector<int> material = vertex_materials(mesh);
    if (m.textured)
        for (std::size_t v = 0; v < n; ++v) {
            if (material[v] < 0)
                continue;
            const auto set = std::size_t(std::max(mesh.materials[std::size_t(material[v])].base_color_texcoord, 0));
            if (set >= mesh.texcoords.size() || mesh.texcoords[set].size() != n)
                continue;
            const glm::vec2 uv = mesh.texcoords[set][v];
            if (std::isfinite(uv.x) && std::isfinite(uv.y) && std::abs(uv.x) < 1e6f && std::abs(uv.y) < 1e6f) {
                m.extra[4 * v + 2] = uv.x;
                m.extra[4 * v + 3] = uv.y;
            }
        }
    upload(m.vertex_extra, GL_ARRAY_BUFFER, m.extra.data(), m.extra.size() * sizeof(float));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
    m.transfer = make_buffer();
    glBindBuffer(GL_ARRAY_BUFFER, m.transfer.get());
    for (int i = 0; i < m.attributes; ++i) {
        glEnableVertexAttribArray(GLuint(4 + i));
        glVertexAttribPointer(GLuint(4 + i), 4, GL_FLOAT, GL_FALSE, GLsizei(m.attributes * 4 * sizeof(float)),
                              reinterpret_cast<const void*>(std::uintptr_t(i) * 4 * sizeof(float)));
    }
    // The triangles in runs of one material each (in mesh order within a run).
    std::vector<std::uint32_t> indices = mesh.indices;
    if (m.textured) {
        std::vector<std::pair<int, std::uint32_t>> order(mesh.triangle_count());
        for (std::size_t t = 0; t < order.size(); ++t) {
            const std::uint32_t part = mesh.triangle_parts[t];
            const int mat = part < mesh.parts.size() ? mesh.parts[part].material : -1;
            order[t] = {mat >= 0 && std::size_t(mat) < mesh.materials.size() ? mat : -1, std::uint32_t(t)};
        }
        std::stable_sort(order.begin(), order.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        for (std::size_t k = 0; k < order.size(); ++k) {
            for (int c = 0; c < 3; ++c)
                indices[3 * k + std::size_t(c)] = mesh.indices[3 * std::size_t(order[k].second) + std::size_t(c)];
            if (m.runs.empty() || m.runs.back().material != order[k].first)
                m.runs.push_back({order[k].first, 3 * k, 0});
            m.runs.back().count += 3;
        }
    } else {
        m.runs.push_back({-1, 0, indices.size()});
    }
    upload(m.indices, GL_ELEMENT_ARRAY_BUFFER, indices.data(), indices.size() * sizeof(std::uint32_t));
    glBindVertexArray(0);
    // A white 1×1 texture for what has no image, and one texture per image (linear RGB, mipmapped, repeating).
    auto make_rgb = [](const float* rgb, int w, int h) {
        Texture t = make_texture();
        glBindTexture(GL_TEXTURE_2D, t.get());
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB16F, w, h, 0, GL_RGB, GL_FLOAT, rgb);
        glGenerateMipmap(GL_TEXTURE_2D);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
        return t;
    };
    const float one[3] = {1.0f, 1.0f, 1.0f};
    m.white = make_rgb(one, 1, 1);
    for (const Image& img : images)
        m.base_color.push_back(img.width > 0 && img.height > 0 ? make_rgb(img.rgb.data(), img.width, img.height)
                                                               : Texture());
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl("model upload");
    return impl;
}

void check_camera(const AoPreviewOptions& c) {
    if (c.width < 1 || c.height < 1 || c.samples < 1 || c.samples > 8 || c.width * c.samples > 16384 ||
        c.height * c.samples > 16384)
        throw Error(fmt::format("image {}x{} with {} samples per axis is out of range; use 1 to 16384 pixels "
                                "(times the samples) per side and 1 to 8 samples",
                                c.width, c.height, c.samples),
                    "camera");
    if (!(c.fov_y_deg > 1.0f && c.fov_y_deg < 170.0f))
        throw Error(fmt::format("field of view {} degrees is out of range; use 1 to 170", c.fov_y_deg), "fov_y_deg");
}

void check_settings(const ModelViewSettings& st, std::size_t rule_size) {
    check_camera(st.camera);
    if (!(st.phong_exponent > 0.0 && st.phong_exponent <= 1e5))
        throw Error(fmt::format("the Phong exponent must be in (0, 100000]; got {}", st.phong_exponent), "phong");
    if (!(st.specular >= 0.0f && std::isfinite(st.specular)))
        throw Error(fmt::format("the specular weight must be ≥ 0; got {}", st.specular), "specular");
    if (!(st.zoom > 0.0f && st.zoom < 1e4f))
        throw Error(fmt::format("the zoom must be in (0, 10000); got {}", st.zoom), "zoom");
    if (st.shading == ModelShading::Visibility &&
        (st.visibility_direction < 0 || std::size_t(st.visibility_direction) >= rule_size))
        throw Error(fmt::format("visibility direction {} is not in the light's rule (0 to {})", st.visibility_direction,
                                rule_size == 0 ? 0 : rule_size - 1),
                    "visibility");
}

} // namespace

ModelRenderer::ModelRenderer(const ViewerModel& model, const SkySource& sky, const SphereRule& light_rule,
                             int light_order)
    : impl_(make_impl(model, sky, light_rule, light_order, true)) {}

ModelRenderer::ModelRenderer(const ViewerModel& model, const SkySource& sky, const SphereRule& light_rule,
                             int light_order, InCurrentContext)
    : impl_(make_impl(model, sky, light_rule, light_order, false)) {}

ModelRenderer::~ModelRenderer() {
    if (impl_)
        impl_->make_current();
}

const ShLight& ModelRenderer::light() const {
    return impl_->light;
}

std::string ModelRenderer::device_description() const {
    if (impl_->own_context)
        return impl_->own_context->description();
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return fmt::format("{}, {}", version ? version : "?", renderer ? renderer : "?");
}

void ModelRenderer::set_albedo(std::span<const glm::vec3> albedo) {
    Impl& m = *impl_;
    if (albedo.size() != m.model->mesh.vertex_count())
        throw Error(fmt::format("{} albedo values for {} vertices", albedo.size(), m.model->mesh.vertex_count()),
                    "albedo");
    m.make_current();
    m.textured = false; // the new albedo is the whole albedo
    glBindBuffer(GL_ARRAY_BUFFER, m.albedo.get());
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(albedo.size() * sizeof(glm::vec3)), albedo.data(), GL_STATIC_DRAW);
}

void ModelRenderer::Impl::draw_frame(const ModelViewSettings& st, int w, int h, ModelFrameStats* stats) {
    update_light(st, stats);
    const ModelShading shading = effective(st.shading);
    const ModelShading upload = shading == ModelShading::Visibility ? ModelShading::Unshadowed : shading;
    if (!have_shading || uploaded_shading != upload)
        upload_transfer(upload);
    const bool sun = light.sun_irradiance != glm::vec3(0.0f) && shading != ModelShading::Visibility;
    if (shading == ModelShading::Visibility)
        update_visibility(glm::vec3(light_rule.points[std::size_t(st.visibility_direction)]), stats);
    else if (sun && st.sun_shadow == SunShadow::Vertex)
        update_visibility(light.sun_direction, stats);
    if (sun && st.sun_shadow == SunShadow::Map)
        update_shadow_map(stats);
    if (shading == ModelShading::Dprt)
        update_glossy(st.phong_exponent);
    const bool map_background = st.sky_background && !sky->is_network();
    if (map_background)
        update_sky_map(stats);

    ensure_target(w, h);
    last_w = w;
    last_h = h;
    const PreviewCamera cam = camera(st);
    const auto t0 = Clock::now();
    target->bind();
    glViewport(0, 0, w, h);
    glDisable(GL_CULL_FACE);
    glClearColor(0.035f, 0.045f, 0.065f, 0.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const float density = float(std::clamp(sky->atmosphere().density_from_altitude(st.altitude_km), 1e-30, 1.0));
    const GLuint bg = st.sky_background ? (background_program ? background_program.get()
                                                               : map_background_program.get())
                                        : 0;
    if (bg) {
        glUseProgram(bg);
        if (background_program) {
            glBindBufferBase(GL_UNIFORM_BUFFER, 0, weights.get());
            glUniform1f(glGetUniformLocation(bg, "u_density"), density);
        } else {
            glActiveTexture(GL_TEXTURE0);
            glBindTexture(GL_TEXTURE_2D, sky_map.get());
            glUniform1i(glGetUniformLocation(bg, "u_sky_map"), 0);
        }
        glUniform3fv(glGetUniformLocation(bg, "u_forward"), 1, glm::value_ptr(cam.forward));
        glUniform3fv(glGetUniformLocation(bg, "u_right"), 1, glm::value_ptr(cam.right));
        glUniform3fv(glGetUniformLocation(bg, "u_up"), 1, glm::value_ptr(cam.up));
        glUniform1f(glGetUniformLocation(bg, "u_tan_half_fov_y"), cam.tan_half_fov_y);
        glUniform1f(glGetUniformLocation(bg, "u_aspect"), cam.aspect);
        glUniform2f(glGetUniformLocation(bg, "u_viewport"), float(w), float(h));
        glUniform3fv(glGetUniformLocation(bg, "u_sun"), 1, glm::value_ptr(light.sun_direction));
        glDisable(GL_DEPTH_TEST);
        glBindVertexArray(empty_vao.get());
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    const GLuint p = model_program.get();
    glUseProgram(p);
    const glm::mat4 clip = clip_from_world(cam);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_clip_from_world"), 1, GL_FALSE, glm::value_ptr(clip));
    glUniform3fv(glGetUniformLocation(p, "u_light"), GLsizei(light.coeffs.size()), glm::value_ptr(light.coeffs.front()));
    glUniform3fv(glGetUniformLocation(p, "u_sun"), 1, glm::value_ptr(light.sun_direction));
    const glm::vec3 sun_e = sun ? light.sun_irradiance : glm::vec3(0.0f);
    glUniform3fv(glGetUniformLocation(p, "u_sun_irradiance"), 1, glm::value_ptr(sun_e));
    glUniform3fv(glGetUniformLocation(p, "u_eye"), 1, glm::value_ptr(cam.eye));
    const int mode = shading == ModelShading::Visibility ? 2 : shading == ModelShading::Dprt ? 1 : 0;
    glUniform1i(glGetUniformLocation(p, "u_mode"), mode);
    glUniform1i(glGetUniformLocation(p, "u_shadow"), int(st.sun_shadow));
    glUniform1f(glGetUniformLocation(p, "u_specular"), st.specular);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, shadow_depth.get());
    glUniform1i(glGetUniformLocation(p, "u_shadow_map"), 1);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, glossy_map.get());
    glUniform1i(glGetUniformLocation(p, "u_glossy"), 2);
    glActiveTexture(GL_TEXTURE0);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_shadow_from_world"), 1, GL_FALSE, glm::value_ptr(shadow_from_world));
    glUniform1f(glGetUniformLocation(p, "u_shadow_offset"), 1.5f * shadow_texel_world);
    glUniform1f(glGetUniformLocation(p, "u_shadow_texel"), 1.0f / float(kShadowMapSize));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUniform1i(glGetUniformLocation(p, "u_base_color"), 3);
    glActiveTexture(GL_TEXTURE3);
    glBindVertexArray(vao.get());
    for (const Run& run : runs) {
        const bool image = textured && run.material >= 0 && base_color[std::size_t(run.material)].get() != 0;
        glBindTexture(GL_TEXTURE_2D, image ? base_color[std::size_t(run.material)].get() : white.get());
        glDrawElements(GL_TRIANGLES, GLsizei(run.count), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(run.first * sizeof(std::uint32_t)));
    }
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE0);
    glFinish();
    check_gl("model draw");
    if (stats) {
        stats->draw_seconds = seconds_since(t0);
        stats->vertices = model->mesh.vertex_count();
        stats->triangles = model->mesh.triangle_count();
        stats->sh_order = light_order;
        stats->shading = shading;
    }
}

Image ModelRenderer::render(const ModelViewSettings& st, ModelFrameStats* stats) {
    Impl& m = *impl_;
    check_settings(st, m.light_rule.size());
    m.make_current();
    if (stats)
        *stats = {};
    const int s = st.camera.samples;
    m.draw_frame(st, st.camera.width * s, st.camera.height * s, stats);
    return Impl::downsample(m.target->read_rgb(), s);
}

unsigned ModelRenderer::draw(const ModelViewSettings& st, ModelFrameStats* stats) {
    Impl& m = *impl_;
    ModelViewSettings one = st;
    one.camera.samples = 1;
    check_settings(one, m.light_rule.size());
    m.make_current();
    if (stats)
        *stats = {};
    m.draw_frame(one, one.camera.width, one.camera.height, stats);
    return m.target->colour_texture();
}

Image ModelRenderer::read_last_draw() const {
    if (!impl_->target)
        throw Error("nothing drawn yet", "draw");
    impl_->make_current();
    return impl_->target->read_rgb();
}

Image ModelRenderer::render_flat(const ModelViewSettings& st, ModelFrameStats* stats) {
    check_camera(st.camera);
    Impl& m = *impl_;
    m.make_current();
    if (stats)
        *stats = {};
    const int s = st.camera.samples, w = st.camera.width * s, h = st.camera.height * s;
    m.ensure_target(w, h);
    const PreviewCamera cam = m.camera(st);
    const auto t0 = Clock::now();
    m.target->bind();
    glViewport(0, 0, w, h);
    glClearColor(0.035f, 0.045f, 0.065f, 0.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const GLuint p = m.flat_program.get();
    glUseProgram(p);
    const glm::mat4 clip = m.clip_from_world(cam);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_clip_from_world"), 1, GL_FALSE, glm::value_ptr(clip));
    glEnable(GL_DEPTH_TEST);
    glBindVertexArray(m.vao.get());
    glDrawElements(GL_TRIANGLES, GLsizei(m.model->mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
    glFinish();
    check_gl("flat draw");
    if (stats) {
        stats->draw_seconds = seconds_since(t0);
        stats->vertices = m.model->mesh.vertex_count();
        stats->triangles = m.model->mesh.triangle_count();
    }
    return Impl::downsample(m.target->read_rgb(), s);
}

} // namespace skybake
