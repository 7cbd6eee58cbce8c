// The model viewer's renderer: relighting of precomputed radiance transfer
// (Sloan, Kautz & Snyder 2002) on OpenGL, one dot product per vertex with the
// GLSL of export_prt_glsl(), under the sky network of seed 000 per pixel. The
// C++ twin is relight() with render_prt_preview() (skybake/prt.h), on the
// same camera (preview_camera()).
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

} // namespace

const char* model_shading_name(ModelShading s) {
    switch (s) {
    case ModelShading::Prt: return "prt";
    case ModelShading::Ao: return "ao";
    case ModelShading::A: return "a";
    case ModelShading::Unshadowed: return "unshadowed";
    }
    return "?";
}

ModelShading parse_model_shading(const std::string& text) {
    for (ModelShading s : {ModelShading::Prt, ModelShading::Ao, ModelShading::A, ModelShading::Unshadowed})
        if (text == model_shading_name(s))
            return s;
    throw Error(fmt::format("unknown shading '{}'; use prt, ao, a or unshadowed", text), "shading");
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
    std::unique_ptr<GlContext> context;
    const SkySource* sky = nullptr;
    const ViewerModel* model = nullptr;
    SkyProjector projector;
    std::unique_ptr<RayQueries> queries;
    int light_order = 3, transfer_order = 3, attributes = 4;
    Program model_program, background_program, flat_program;
    Buffer weights, positions, normals, albedo, sun_visible, transfer, indices;
    VertexArray vao, empty_vao;
    std::unique_ptr<RenderTarget> target;
    ShLight light;
    bool have_light = false;
    SkyLightSettings light_settings;
    glm::vec3 sun_for_visibility{0.0f};
    bool have_visibility = false;
    ModelShading uploaded_shading = ModelShading::Prt;
    bool have_shading = false;

    Impl(const ViewerModel& m, const SkySource& s, const SphereRule& rule, int order)
        : sky(&s), model(&m), projector(order, rule), light_order(order) {}

    ModelShading effective(ModelShading s) const {
        if (!model->has_transfer())
            return ModelShading::Unshadowed;
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
        if (s == ModelShading::Prt) {
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
            if (stats)
                stats->light_seconds = seconds_since(t0);
        }
        const bool sun = light.sun_irradiance != glm::vec3(0.0f);
        if (sun && (!have_visibility || light.sun_direction != sun_for_visibility)) {
            const auto t0 = Clock::now();
            const std::vector<float> v = sun_visibility(model->mesh, light.sun_direction, *queries);
            glBindBuffer(GL_ARRAY_BUFFER, sun_visible.get());
            glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_DYNAMIC_DRAW);
            sun_for_visibility = light.sun_direction;
            have_visibility = true;
            if (stats)
                stats->sun_seconds = seconds_since(t0);
        }
    }

    void ensure_target(int w, int h) {
        if (!target || target->width() != w || target->height() != h)
            target = std::make_unique<RenderTarget>(w, h);
    }

    glm::mat4 clip_from_world(const PreviewCamera& c) const {
        const float dist = glm::length(c.eye - c.centre);
        const float near = std::max(dist - 1.5f * c.radius, 1e-3f * dist);
        const float far = dist + 1.5f * c.radius;
        const glm::mat4 view = glm::lookAt(c.eye, c.eye + c.forward, c.up);
        const glm::mat4 proj = glm::perspective(2.0f * std::atan(c.tan_half_fov_y), c.aspect, near, far);
        return proj * view;
    }

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

ModelRenderer::ModelRenderer(const ViewerModel& model, const SkySource& sky, const SphereRule& light_rule,
                             int light_order) {
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
    impl_ = std::make_unique<Impl>(model, sky, light_rule, light_order);
    Impl& m = *impl_;
    m.transfer_order = transfer_order;
    const int channels = model.has_transfer() ? model.transfer.channels : 1;
    m.attributes = (channels * sh_count(transfer_order) + 3) / 4;
    m.context = create_headless_context();
    m.context->make_current();
    GLint max_attribs = 0;
    glGetIntegerv(GL_MAX_VERTEX_ATTRIBS, &max_attribs);
    if (4 + m.attributes > max_attribs)
        throw Error(fmt::format("a transfer of order {} ({} channel{}) needs {} vertex attributes; this driver has {}",
                                transfer_order, channels, channels == 1 ? "" : "s", 4 + m.attributes, max_attribs),
                    "order");
    m.queries = make_ray_queries("embree");
    m.queries->set_mesh(model.mesh);

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
        s.pieces = {kVersion, defines, fmt::format("#define {}\n", name), body, render::shaders::model_stages};
        return s;
    };
    m.model_program = link_program("model", stage(prt, "SKYBAKE_STAGE_MODEL_VS"), stage("", "SKYBAKE_STAGE_MODEL_FS"));
    m.flat_program = link_program("flat", stage("", "SKYBAKE_STAGE_FLAT_VS"), stage("", "SKYBAKE_STAGE_FLAT_FS"));
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
        m.background_program = link_program("background", stage("", "SKYBAKE_STAGE_BACKGROUND_VS"),
                                            stage(network, "SKYBAKE_STAGE_BACKGROUND_FS"));
        const GLuint block = glGetUniformBlockIndex(m.background_program.get(), "SkybakeSkyWeights");
        if (block != GL_INVALID_INDEX)
            glUniformBlockBinding(m.background_program.get(), block, 0);
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
    upload(m.albedo, GL_ARRAY_BUFFER, model.albedo.data(), n * sizeof(glm::vec3));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    const std::vector<float> zeros(n, 0.0f);
    upload(m.sun_visible, GL_ARRAY_BUFFER, zeros.data(), n * sizeof(float));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
    m.transfer = make_buffer();
    glBindBuffer(GL_ARRAY_BUFFER, m.transfer.get());
    for (int i = 0; i < m.attributes; ++i) {
        glEnableVertexAttribArray(GLuint(4 + i));
        glVertexAttribPointer(GLuint(4 + i), 4, GL_FLOAT, GL_FALSE, GLsizei(m.attributes * 4 * sizeof(float)),
                              reinterpret_cast<const void*>(std::uintptr_t(i) * 4 * sizeof(float)));
    }
    upload(m.indices, GL_ELEMENT_ARRAY_BUFFER, mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
    glBindVertexArray(0);
    check_gl("model upload");
}

ModelRenderer::~ModelRenderer() {
    if (impl_ && impl_->context)
        impl_->context->make_current();
}

const ShLight& ModelRenderer::light() const {
    return impl_->light;
}

std::string ModelRenderer::device_description() const {
    return impl_->context->description();
}

namespace {
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
} // namespace

Image ModelRenderer::render(const ModelViewSettings& st, ModelFrameStats* stats) {
    check_camera(st.camera);
    Impl& m = *impl_;
    m.context->make_current();
    if (stats)
        *stats = {};
    m.update_light(st, stats);
    const ModelShading shading = m.effective(st.shading);
    if (!m.have_shading || m.uploaded_shading != shading)
        m.upload_transfer(shading);
    const int s = st.camera.samples, w = st.camera.width * s, h = st.camera.height * s;
    m.ensure_target(w, h);
    const PreviewCamera cam = preview_camera(m.model->mesh, st.camera);
    const auto t0 = Clock::now();
    m.target->bind();
    glViewport(0, 0, w, h);
    glDisable(GL_CULL_FACE);
    glClearColor(0.035f, 0.045f, 0.065f, 0.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const float density = float(std::clamp(m.sky->atmosphere().density_from_altitude(st.altitude_km), 1e-30, 1.0));
    if (st.sky_background && m.background_program) {
        const GLuint p = m.background_program.get();
        glUseProgram(p);
        glBindBufferBase(GL_UNIFORM_BUFFER, 0, m.weights.get());
        glUniform3fv(glGetUniformLocation(p, "u_forward"), 1, glm::value_ptr(cam.forward));
        glUniform3fv(glGetUniformLocation(p, "u_right"), 1, glm::value_ptr(cam.right));
        glUniform3fv(glGetUniformLocation(p, "u_up"), 1, glm::value_ptr(cam.up));
        glUniform1f(glGetUniformLocation(p, "u_tan_half_fov_y"), cam.tan_half_fov_y);
        glUniform1f(glGetUniformLocation(p, "u_aspect"), cam.aspect);
        glUniform2f(glGetUniformLocation(p, "u_viewport"), float(w), float(h));
        glUniform3fv(glGetUniformLocation(p, "u_sun"), 1, glm::value_ptr(m.light.sun_direction));
        glUniform1f(glGetUniformLocation(p, "u_density"), density);
        glDisable(GL_DEPTH_TEST);
        glBindVertexArray(m.empty_vao.get());
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    const GLuint p = m.model_program.get();
    glUseProgram(p);
    const glm::mat4 clip = m.clip_from_world(cam);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_clip_from_world"), 1, GL_FALSE, glm::value_ptr(clip));
    glUniform3fv(glGetUniformLocation(p, "u_light"), GLsizei(m.light.coeffs.size()),
                 glm::value_ptr(m.light.coeffs.front()));
    glUniform3fv(glGetUniformLocation(p, "u_sun"), 1, glm::value_ptr(m.light.sun_direction));
    const glm::vec3 sun_e = m.have_visibility ? m.light.sun_irradiance : glm::vec3(0.0f);
    glUniform3fv(glGetUniformLocation(p, "u_sun_irradiance"), 1, glm::value_ptr(sun_e));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glBindVertexArray(m.vao.get());
    glDrawElements(GL_TRIANGLES, GLsizei(m.model->mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
    glFinish();
    check_gl("model draw");
    if (stats) {
        stats->draw_seconds = seconds_since(t0);
        stats->vertices = m.model->mesh.vertex_count();
        stats->triangles = m.model->mesh.triangle_count();
        stats->sh_order = m.light_order;
        stats->shading = shading;
    }
    return Impl::downsample(m.target->read_rgb(), s);
}

Image ModelRenderer::render_flat(const ModelViewSettings& st, ModelFrameStats* stats) {
    check_camera(st.camera);
    Impl& m = *impl_;
    m.context->make_current();
    if (stats)
        *stats = {};
    const int s = st.camera.samples, w = st.camera.width * s, h = st.camera.height * s;
    m.ensure_target(w, h);
    const PreviewCamera cam = preview_camera(m.model->mesh, st.camera);
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
