// The planet renderer: Pietras & Rudnicki (seed 000), sections IV, VI and VII
// on OpenGL. The sky shell and the planet mesh evaluate the sky function per
// vertex (the seed's vertex program) or per pixel; the network is the GLSL of
// `skybake sky export` with its weights in a uniform block, the tables are one
// R32F texture, and the shading functions are the GLSL twin of the CPU
// renderer's (shaders/atmosphere.glsl). Positions go to the GPU relative to
// the camera (Cozzi & Ring, 3D Engine Design for Virtual Globes, 2011), depth
// is reversed-Z in a float buffer with an infinite far plane.
#include <chrono>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include "render/planet_scene.h"
#include "render/shaders.h"
#include "sky/device.h"
#include "skybake/error.h"

namespace skybake::render {

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr const char* kVersion = "#version 330 core\n";

std::vector<glm::vec3> icosphere_directions(int level, std::vector<std::uint32_t>& tris) {
    const float p = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<glm::vec3> v = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                                {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
    for (glm::vec3& x : v)
        x = glm::normalize(x);
    tris = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
            3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
    for (int l = 0; l < level; ++l) {
        std::vector<std::uint32_t> next;
        std::unordered_map<std::uint64_t, std::uint32_t> mid;
        auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const std::uint64_t k = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            auto it = mid.find(k);
            if (it != mid.end())
                return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[k] = std::uint32_t(v.size() - 1);
        };
        for (std::size_t t = 0; t < tris.size(); t += 3) {
            const std::uint32_t a = tris[t], b = tris[t + 1], c = tris[t + 2];
            const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        tris.swap(next);
    }
    return v;
}

ShaderSource stage(const std::string& defines, const std::string& network, const char* stage_define) {
    ShaderSource s;
    s.pieces = {kVersion,
                defines,
                fmt::format("#define {}\n", stage_define),
                shaders::shared_source,
                shaders::tone_curve,
                network,
                shaders::atmosphere,
                shaders::grid4_shared,
                shaders::sky_shared,
                shaders::shade_shared,
                shaders::planet_stages,
                shaders::screen_stages};
    if (const char* bad = std::getenv("SKYBAKE_GL_TEST_BAD_SHADER"); bad && *bad == '1')
        s.pieces.push_back("this is not GLSL;\n"); // test hook: a shader that fails to compile
    return s;
}

GLint loc(GLuint p, const char* name) {
    return glGetUniformLocation(p, name);
}

} // namespace

PlanetScene::PlanetScene(const GlContext& context, const SkyModel& model, const NeuralSky* net,
                         const PlanetRenderOptions& options)
    : options_(options), model_(model), clip_control_(context.has_clip_control()), mesh_([&] {
          ClodOptions c;
          c.planet_radius_km = model.atmosphere().planet_radius_km;
          c.relief = options.relief;
          c.max_error_px = options.max_error_px;
          c.max_triangles = options.max_triangles;
          return c;
      }()) {
    if (options.sky == PlanetSky::Network && !net)
        throw Error("the network sky needs weights", "PlanetRenderOptions::sky");
    if (!(options.max_error_px > 0.0) || options.max_triangles < 20 || options.sky_shell_level < 0 ||
        options.sky_shell_level > 7)
        throw Error("max_error_px must be > 0, max_triangles >= 20 and sky_shell_level 0 to 7", "PlanetRenderOptions");
    std::string defines =
        options.sky == PlanetSky::Reference ? "#define SKYBAKE_SKY_REFERENCE\n" : "#define SKYBAKE_SKY_NETWORK\n";
    if (options.shading == ShadingRate::Pixel)
        defines += "#define SKYBAKE_PER_PIXEL\n";
    std::string network;
    if (options.sky == PlanetSky::Network) {
        ShaderExportOptions eo;
        eo.uniform_block = true;
        network = export_neural_sky(*net, ExportLanguage::Glsl, eo);
        const std::vector<float> data = neural_sky_uniform_data(*net);
        GLint max_block = 0;
        glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &max_block);
        if (GLint(data.size() * sizeof(float)) > max_block)
            throw Error(fmt::format("the network's {} weights need a {}-byte uniform block; this driver allows {}",
                                    net->weights.size(), data.size() * sizeof(float), max_block),
                        "OpenGL");
        weights_ = make_buffer();
        glBindBuffer(GL_UNIFORM_BUFFER, weights_.get());
        glBufferData(GL_UNIFORM_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    }
    const char* sky_vs = options.shading == ShadingRate::Pixel ? "SKYBAKE_STAGE_FULL_SCREEN_VS" : "SKYBAKE_STAGE_SKY_VS";
    sky_ = link_program("sky", stage(defines, network, sky_vs),
                        stage(defines, network, "SKYBAKE_STAGE_SKY_FS"));
    planet_ = link_program("planet", stage(defines, network, "SKYBAKE_STAGE_PLANET_VS"),
                           stage(defines, network, "SKYBAKE_STAGE_PLANET_FS"));
    flat_ = link_program("flat", stage(defines, network, "SKYBAKE_STAGE_FLAT_VS"),
                         stage(defines, network, "SKYBAKE_STAGE_FLAT_FS"));
    tone_ = link_program("tone", stage(defines, network, "SKYBAKE_STAGE_FULL_SCREEN_VS"),
                         stage(defines, network, "SKYBAKE_STAGE_TONE_FS"));
    for (GLuint p : {sky_.get(), planet_.get()}) {
        const GLuint block = glGetUniformBlockIndex(p, "SkybakeSkyWeights");
        if (block != GL_INVALID_INDEX)
            glUniformBlockBinding(p, block, 0);
    }

    // Optical-length tables: one R32F texture, components stacked by rows.
    const OpticalLengthTables& t = model.tables();
    rows_ = t.rows();
    cols_ = t.columns();
    std::vector<float> texels;
    for (int k = 0; k < t.components(); ++k)
        texels.insert(texels.end(), t.length_table(k).begin(), t.length_table(k).end());
    tables_ = make_texture();
    glBindTexture(GL_TEXTURE_2D, tables_.get());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, cols_, rows_ * t.components(), 0, GL_RED, GL_FLOAT, texels.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);

    // Multiple scattering: the orders grid or ψms, then the sky irradiance, as
    // RGB triples in one buffer texture (always bound, empty or not, so that
    // the sampler never shares unit 0 with the tables).
    {
        const sky::MultipleHD& m = sky::atmosphere_hd(model).ms;
        std::vector<float> ms;
        if (m.orders)
            ms.assign(m.orders, m.orders + std::size_t(m.nr) * 2u * std::size_t(m.nmu) * std::size_t(m.nmus) *
                                               std::size_t(m.nnu) * 3u);
        ms_psi_first_ = int(ms.size() / 3);
        if (m.psi)
            ms.insert(ms.end(), m.psi, m.psi + std::size_t(m.psi_nr) * std::size_t(m.psi_nmus) * 3u);
        ms_irr_first_ = int(ms.size() / 3);
        if (m.irradiance)
            ms.insert(ms.end(), m.irradiance, m.irradiance + std::size_t(m.irr_nr) * std::size_t(m.irr_nmus) * 3u);
        if (ms.empty())
            ms.assign(3, 0.0f);
        GLint max_texels = 0;
        glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
        if (GLint(ms.size()) > max_texels)
            throw Error(fmt::format("the multiple-scattering tables need {} texels of a buffer texture; this driver "
                                    "allows {}",
                                    ms.size(), max_texels),
                        "OpenGL");
        ms_buf_ = make_buffer();
        glBindBuffer(GL_TEXTURE_BUFFER, ms_buf_.get());
        glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(ms.size() * sizeof(float)), ms.data(), GL_STATIC_DRAW);
        ms_tex_ = make_texture();
        glBindTexture(GL_TEXTURE_BUFFER, ms_tex_.get());
        glTexBuffer(GL_TEXTURE_BUFFER, GL_R32F, ms_buf_.get());
        glBindTexture(GL_TEXTURE_BUFFER, 0);
        glBindBuffer(GL_TEXTURE_BUFFER, 0);
    }

    // Sky shell directions (per vertex) and the mesh buffers.
    empty_vao_ = make_vertex_array();
    // Sky dome (per vertex, inside the atmosphere): rings of constant angle to
    // the horizon around the local vertical, rebuilt for each view, so that
    // one ring lies on the horizon and the rings crowd near it, where the sky
    // changes fastest; the triangles never straddle the horizon.
    const int az = 3 << std::min(options.sky_shell_level, 7); // 96 at level 5
    // Degrees above the horizon: geometric from 0.05° until the steps reach
    // the azimuthal spacing, then uniform (square cells) up to 180°.
    const double step = 360.0 / double(az);
    std::vector<double> offsets = {0.0};
    for (double e = 0.05; e < 180.0;) {
        offsets.push_back(e);
        e = e * 1.5 < e + step ? e * 1.5 : e + step;
    }
    offsets.push_back(180.0);
    dome_rings_ = offsets;
    dome_azimuths_ = az;
    std::vector<std::uint32_t> dome_tris;
    const std::uint32_t ring_n = std::uint32_t(az + 1);
    for (std::uint32_t r = 0; r + 1 < std::uint32_t(offsets.size()); ++r)
        for (std::uint32_t a = 0; a < std::uint32_t(az); ++a) {
            const std::uint32_t v00 = r * ring_n + a, v01 = v00 + 1, v10 = v00 + ring_n, v11 = v10 + 1;
            dome_tris.insert(dome_tris.end(), {v00, v10, v01, v01, v10, v11});
        }
    dome_count_ = GLsizei(dome_tris.size());
    dome_vao_ = make_vertex_array();
    dome_vbo_ = make_buffer();
    dome_ibo_ = make_buffer();
    glBindVertexArray(dome_vao_.get());
    glBindBuffer(GL_ARRAY_BUFFER, dome_vbo_.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, dome_ibo_.get());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(dome_tris.size() * 4), dome_tris.data(), GL_STATIC_DRAW);

    // The top-of-atmosphere shell for observers outside the atmosphere.
    std::vector<std::uint32_t> shell_tris;
    for (const glm::vec3& d : icosphere_directions(6, shell_tris))
        shell_dirs_.push_back(glm::normalize(glm::dvec3(d)));
    shell_count_ = GLsizei(shell_tris.size());
    shell_vao_ = make_vertex_array();
    shell_vbo_ = make_buffer();
    shell_ibo_ = make_buffer();
    glBindVertexArray(shell_vao_.get());
    glBindBuffer(GL_ARRAY_BUFFER, shell_vbo_.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, shell_ibo_.get());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(shell_tris.size() * 4), shell_tris.data(), GL_STATIC_DRAW);

    mesh_vao_ = make_vertex_array();
    pos_vbo_ = make_buffer();
    nrm_vbo_ = make_buffer();
    mesh_ibo_ = make_buffer();
    glBindVertexArray(mesh_vao_.get());
    glBindBuffer(GL_ARRAY_BUFFER, pos_vbo_.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ARRAY_BUFFER, nrm_vbo_.get());
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh_ibo_.get());
    glBindVertexArray(0);
    check_gl("planet renderer setup");
}

PlanetScene::~PlanetScene() = default;

void PlanetScene::set_uniforms(GLuint p, const PlanetView& v, const Basis& b) const {
    glUseProgram(p);
    const Atmosphere& atm = model_.atmosphere();
    // u_render mirrors sky::RenderHD (sky/shade_shared.h) field by field, with
    // the data handles as texture rows and texel offsets.
    sky::RenderHD r;
    r.atm = sky::atmosphere_hd(model_);
    const glm::dvec3 eye = shading_eye(v);
    const double eye_r = glm::length(eye);
    r.eye_r = float(eye_r);
    r.eye_h = float(eye_r - atm.planet_radius_km);
    r.zenith = glm::vec3(eye / eye_r);
    r.sun = glm::normalize(glm::vec3(v.sun));
    sky::set_scene_hd(r, model_, options_.published_ground, options_.sun_disc);
    const auto u1i = [&](const std::string& n, int x) { glUniform1i(loc(p, ("u_render." + n).c_str()), x); };
    const auto u1f = [&](const std::string& n, float x) { glUniform1f(loc(p, ("u_render." + n).c_str()), x); };
    const auto u3f = [&](const std::string& n, const glm::vec3& x) {
        glUniform3f(loc(p, ("u_render." + n).c_str()), x.x, x.y, x.z);
    };
    const sky::AtmosphereHD& a = r.atm;
    u1f("atm.R0", a.R0);
    u1f("atm.Rtop", a.Rtop);
    u1i("atm.count", a.count);
    for (int k = 0; k < a.count; ++k) {
        const sky::ComponentHD& c = a.comp[k];
        const std::string n = fmt::format("atm.comp[{}].", k);
        u1i(n + "profile", c.profile);
        u1f(n + "inv_scale_height", c.inv_scale_height);
        u1f(n + "tent_center", c.tent_center);
        u1f(n + "inv_tent_half_width", c.inv_tent_half_width);
        u3f(n + "sca", c.sca);
        u3f(n + "ext", c.ext);
        u1i(n + "phase", c.phase);
        u1f(n + "g", c.g);
        u1i(n + "axis", c.axis);
        u1i(n + "table.L", k * rows_);
        u1i(n + "table.rows", rows_);
        u1i(n + "table.cols", cols_);
    }
    const sky::MultipleHD& m = a.ms;
    u1i("atm.ms.method", m.method);
    u1f("atm.ms.mu_s_min", m.mu_s_min);
    u1f("atm.ms.x_horizon", m.x_horizon);
    u1i("atm.ms.orders", 0);
    u1i("atm.ms.nr", m.nr);
    u1i("atm.ms.nmu", m.nmu);
    u1i("atm.ms.nmus", m.nmus);
    u1i("atm.ms.nnu", m.nnu);
    u1i("atm.ms.psi", ms_psi_first_);
    u1i("atm.ms.psi_nr", m.psi ? m.psi_nr : 0);
    u1i("atm.ms.psi_nmus", m.psi ? m.psi_nmus : 0);
    u1i("atm.ms.irradiance", ms_irr_first_);
    u1i("atm.ms.irr_nr", m.irradiance ? m.irr_nr : 0);
    u1i("atm.ms.irr_nmus", m.irradiance ? m.irr_nmus : 0);
    u1f("eye_r", r.eye_r);
    u1f("eye_h", r.eye_h);
    u3f("zenith", r.zenith);
    u3f("sun", r.sun);
    u1i("steps", r.steps);
    u1i("spacing", r.spacing);
    u3f("albedo", r.albedo);
    u1i("published_ground", r.published_ground);
    u3f("irradiance", r.irradiance);
    u1f("sun_cos_radius", r.sun_cos_radius);
    u1f("sun_disc_radiance", r.sun_disc_radiance);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tables_.get());
    glUniform1i(loc(p, "u_tables"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_BUFFER, ms_tex_.get());
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(loc(p, "u_ms"), 1);
    glUniformMatrix4fv(loc(p, "u_view_proj"), 1, GL_FALSE, glm::value_ptr(b.view_proj));
    glUniform3f(loc(p, "u_forward"), b.forward.x, b.forward.y, b.forward.z);
    glUniform3f(loc(p, "u_right"), b.right.x, b.right.y, b.right.z);
    glUniform3f(loc(p, "u_cam_up"), b.up.x, b.up.y, b.up.z);
    glUniform1f(loc(p, "u_tan_half_fov"), b.tan_half_fov);
    glUniform2f(loc(p, "u_viewport"), float(v.width), float(v.height));
    glUniform1i(loc(p, "u_relief"), options_.relief.amplitude_km > 0.0 ? 1 : 0);
    if (weights_)
        glBindBufferBase(GL_UNIFORM_BUFFER, 0, weights_.get());
}

PlanetScene::Basis PlanetScene::basis(const PlanetView& v) const {
    Basis b;
    b.forward = glm::normalize(glm::vec3(v.forward));
    // As sky::make_render_hd: right = forward × up, up = right × forward.
    b.right = glm::normalize(glm::cross(b.forward, glm::vec3(v.up)));
    b.up = glm::cross(b.right, b.forward);
    b.tan_half_fov = float(std::tan(0.5 * v.fov_x_deg * kDeg));
    const float sx = 1.0f / b.tan_half_fov;
    const float sy = 1.0f / (b.tan_half_fov * float(v.height) / float(v.width));
    glm::mat4 view(1.0f); // rows: right, up, −forward
    for (int i = 0; i < 3; ++i) {
        view[i][0] = b.right[i];
        view[i][1] = b.up[i];
        view[i][2] = -b.forward[i];
    }
    // Reversed-Z, infinite far plane: depth = near / distance along the view axis.
    const float near_km = 1e-7f; // 0.1 mm: the ground 1 cm below the eye stays in view
    glm::mat4 proj(0.0f);
    proj[0][0] = sx;
    proj[1][1] = sy;
    proj[2][3] = -1.0f;
    proj[3][2] = near_km;
    b.view_proj = proj * view;
    return b;
}

PlanetCamera PlanetScene::clod_camera(const PlanetView& v, const Basis& b) const {
    PlanetCamera c;
    c.position_km = v.eye_km;
    c.forward = glm::dvec3(b.forward);
    c.up = glm::dvec3(b.up);
    c.fov_y_rad = 2.0 * std::atan(double(b.tan_half_fov) * double(v.height) / double(v.width));
    c.viewport_width = v.width;
    c.viewport_height = v.height;
    return c;
}

glm::dvec3 PlanetScene::geometric_eye(const PlanetView& v) const {
    // An eye exactly on the ground (altitude 0, the seed's sea level) would sit
    // on a vertex or in the plane of the triangles around it: the mesh is
    // drawn from 1 cm above (the shading keeps the true altitude).
    // With relief, an eye inside the terrain is lifted to 1 m above it (for
    // the shading too: see shading_eye).
    const double r = glm::length(v.eye_km);
    double lowest = model_.atmosphere().planet_radius_km + 1e-5;
    if (options_.relief.amplitude_km > 0.0)
        lowest += relief_height_km(options_.relief, v.eye_km / r) + 1e-3;
    return r < lowest ? v.eye_km * (lowest / r) : v.eye_km;
}

glm::dvec3 PlanetScene::shading_eye(const PlanetView& v) const {
    return options_.relief.amplitude_km > 0.0 ? geometric_eye(v) : v.eye_km;
}

void PlanetScene::update_mesh(const PlanetView& v, PlanetFrameStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    const Basis b = basis(v);
    PlanetCamera cam = clod_camera(v, b);
    cam.position_km = geometric_eye(v);
    const ClodStats st = mesh_.update(cam);
    mesh_.indices(indices_);
    mesh_.vertices(cam.position_km, positions_, normals_);
    glBindBuffer(GL_ARRAY_BUFFER, pos_vbo_.get());
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(positions_.size() * 4), positions_.data(), GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, nrm_vbo_.get());
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(normals_.size() * 4), normals_.data(), GL_STREAM_DRAW);
    glBindVertexArray(mesh_vao_.get());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices_.size() * 4), indices_.data(), GL_STREAM_DRAW);
    glBindVertexArray(0);
    mesh_count_ = GLsizei(indices_.size());
    if (stats) {
        stats->triangles = st.triangles;
        stats->max_error_px = st.max_error_px;
        stats->clod_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
}

void PlanetScene::draw(const PlanetView& v, bool flat, PlanetFrameStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    const Basis b = basis(v);
    if (clip_control_)
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_BLEND);
    std::size_t sky_tris = 0;
    if (!flat) {
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
        glDisable(GL_CULL_FACE);
        set_uniforms(sky_.get(), v, b);
        if (options_.shading == ShadingRate::Pixel) {
            glBindVertexArray(empty_vao_.get());
            glDrawArrays(GL_TRIANGLES, 0, 3);
            sky_tris = 1;
        } else if (glm::length(v.eye_km) <= model_.atmosphere().top_radius_km) {
            // The dome's directions: from the horizon (its dip below the local
            // horizontal) up over the zenith to the horizon on the other side.
            const glm::dvec3 up = glm::normalize(v.eye_km);
            const glm::dvec3 east =
                glm::normalize(glm::cross(std::abs(up.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0), up));
            const glm::dvec3 north = glm::cross(up, east);
            const double R0 = model_.atmosphere().planet_radius_km, r = std::max(glm::length(v.eye_km), R0);
            const double dip = std::acos(std::min(1.0, R0 / r)); // radians below the horizontal
            dome_dirs_.clear();
            for (double off : dome_rings_) {
                // Angle from the horizon direction, over the zenith: elevation e = off − dip, up to 90°, then down the
                // far side.
                const double e = off * kDeg - dip;
                for (int a = 0; a <= dome_azimuths_; ++a) {
                    const double phi = 2.0 * 3.14159265358979323846 * double(a) / double(dome_azimuths_);
                    const glm::dvec3 h = std::cos(phi) * east + std::sin(phi) * north;
                    const glm::dvec3 d = std::cos(e) * h + std::sin(e) * up;
                    dome_dirs_.push_back(glm::vec3(d));
                }
            }
            glBindBuffer(GL_ARRAY_BUFFER, dome_vbo_.get());
            glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(dome_dirs_.size() * sizeof(glm::vec3)), dome_dirs_.data(),
                         GL_STREAM_DRAW);
            glUniform1i(loc(sky_.get(), "u_shell"), 0);
            glBindVertexArray(dome_vao_.get());
            glDrawElements(GL_TRIANGLES, dome_count_, GL_UNSIGNED_INT, nullptr);
            sky_tris = std::size_t(dome_count_ / 3);
        } else {
            const double top = model_.atmosphere().top_radius_km;
            shell_rel_.resize(shell_dirs_.size() * 3);
            for (std::size_t i = 0; i < shell_dirs_.size(); ++i) {
                const glm::dvec3 p = shell_dirs_[i] * top - geometric_eye(v);
                shell_rel_[3 * i] = float(p.x);
                shell_rel_[3 * i + 1] = float(p.y);
                shell_rel_[3 * i + 2] = float(p.z);
            }
            glBindBuffer(GL_ARRAY_BUFFER, shell_vbo_.get());
            glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(shell_rel_.size() * 4), shell_rel_.data(), GL_STREAM_DRAW);
            glUniform1i(loc(sky_.get(), "u_shell"), 1);
            glEnable(GL_CULL_FACE); // the near half of the shell
            glCullFace(GL_BACK);
            glFrontFace(GL_CCW);
            glBindVertexArray(shell_vao_.get());
            glDrawElements(GL_TRIANGLES, shell_count_, GL_UNSIGNED_INT, nullptr);
            sky_tris = std::size_t(shell_count_ / 3);
        }
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    set_uniforms(flat ? flat_.get() : planet_.get(), v, b);
    glBindVertexArray(mesh_vao_.get());
    glDrawElements(GL_TRIANGLES, mesh_count_, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
    glFinish();
    check_gl("planet draw");
    if (stats) {
        stats->sky_triangles = sky_tris;
        stats->draw_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
}

void PlanetScene::tone_map(GLuint texture, int width, int height, float exposure_ev, ToneCurve curve) {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glViewport(0, 0, width, height);
    glUseProgram(tone_.get());
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, texture);
    glUniform1i(loc(tone_.get(), "u_image"), 1);
    glUniform1f(loc(tone_.get(), "u_exposure_scale"), std::exp2(exposure_ev));
    glUniform1i(loc(tone_.get(), "u_tone"), int(curve)); // tone_curve()'s values (core/tone_curve.h)
    glBindVertexArray(empty_vao_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
}

} // namespace skybake::render

namespace skybake {

using namespace render;

struct PlanetRenderer::Impl {
    std::unique_ptr<GlContext> context;
    std::unique_ptr<PlanetScene> scene;
    std::unique_ptr<RenderTarget> target;
};

PlanetRenderer::PlanetRenderer(const SkyModel& tables, const NeuralSky* net, const PlanetRenderOptions& options)
    : impl_(std::make_unique<Impl>()) {
    impl_->context = create_headless_context();
    impl_->scene = std::make_unique<PlanetScene>(*impl_->context, tables, net, options);
}

PlanetRenderer::~PlanetRenderer() {
    if (impl_ && impl_->context) {
        impl_->context->make_current();
        impl_->target.reset();
        impl_->scene.reset();
    }
}

std::string PlanetRenderer::device_description() const {
    return impl_->context->description();
}

namespace {
void check_view(const PlanetView& v) {
    if (v.width < 1 || v.height < 1 || v.width > 16384 || v.height > 16384)
        throw Error("image size must be 1 to 16384 pixels on each side", "PlanetView::width/height");
    if (!(v.fov_x_deg > 0.0 && v.fov_x_deg < 180.0))
        throw Error("the field of view must be in (0, 180) degrees", "PlanetView::fov_x_deg");
    if (!(glm::length(v.forward) > 0.5 && std::isfinite(glm::length(v.eye_km)) && glm::length(v.sun) > 0.5))
        throw Error("the view needs a finite eye and unit forward and sun directions", "PlanetView");
}
} // namespace

Image PlanetRenderer::render(const PlanetView& v, PlanetFrameStats* stats) {
    check_view(v);
    impl_->context->make_current();
    if (!impl_->target || impl_->target->width() != v.width || impl_->target->height() != v.height)
        impl_->target = std::make_unique<RenderTarget>(v.width, v.height);
    impl_->target->bind();
    impl_->scene->update_mesh(v, stats);
    impl_->scene->draw(v, false, stats);
    return impl_->target->read_rgb();
}

Image PlanetRenderer::render_flat(const PlanetView& v, PlanetFrameStats* stats) {
    check_view(v);
    impl_->context->make_current();
    if (!impl_->target || impl_->target->width() != v.width || impl_->target->height() != v.height)
        impl_->target = std::make_unique<RenderTarget>(v.width, v.height);
    impl_->target->bind();
    impl_->scene->update_mesh(v, stats);
    impl_->scene->draw(v, true, stats);
    return impl_->target->read_rgb();
}

PlanetView planet_view_from_settings(const Atmosphere& atm, const SkyRenderSettings& s) {
    if (s.view != SkyView::Camera)
        throw Error("the OpenGL renderer draws camera views only", "SkyRenderSettings::view");
    PlanetView v;
    v.eye_km = glm::dvec3(0.0, 0.0, atm.planet_radius_km + s.altitude_km);
    // The camera of sky::make_render_hd.
    const glm::vec3 f = sky::direction_from_angles(float(s.yaw_deg * kDeg), float(s.pitch_deg * kDeg));
    glm::vec3 right = glm::cross(f, glm::vec3(0.0f, 0.0f, 1.0f));
    if (glm::length(right) < 1e-6f)
        right = glm::vec3(std::sin(float(s.yaw_deg * kDeg)), -std::cos(float(s.yaw_deg * kDeg)), 0.0f);
    right = glm::normalize(right);
    v.forward = glm::dvec3(f);
    v.up = glm::dvec3(glm::cross(right, f));
    v.fov_x_deg = s.fov_deg;
    v.width = s.width;
    v.height = s.height;
    v.sun = glm::dvec3(sky::direction_from_angles(float(s.sun_azimuth_deg * kDeg), float(s.sun_elevation_deg * kDeg)));
    return v;
}

PlanetView planet_viewer_view(const glm::dvec3& eye_km, double yaw_deg, double pitch_deg, double sun_azimuth_deg,
                              double sun_elevation_deg, int width, int height) {
    // Local frame at the eye: up, and a horizontal east/north basis (+x, +y above the pole).
    const glm::dvec3 up = glm::normalize(eye_km);
    glm::dvec3 east = glm::cross(glm::dvec3(0, 0, 1), up);
    east = glm::length(east) < 1e-9 ? glm::dvec3(1, 0, 0) : glm::normalize(east);
    const glm::dvec3 north = glm::cross(up, east);
    const double yaw = yaw_deg * kDeg, pitch = pitch_deg * kDeg;
    const glm::dvec3 heading = std::cos(yaw) * east + std::sin(yaw) * north;
    const glm::dvec3 right = glm::cross(heading, up); // horizontal, whatever the pitch
    PlanetView v;
    v.eye_km = eye_km;
    v.forward = std::cos(pitch) * heading + std::sin(pitch) * up;
    v.up = glm::cross(right, v.forward); // straight down too: the heading at the top of the screen
    v.fov_x_deg = 90.0;
    v.width = width;
    v.height = height;
    v.sun = glm::dvec3(sky::direction_from_angles(float(sun_azimuth_deg * kDeg), float(sun_elevation_deg * kDeg)));
    return v;
}

double planet_viewer_default_pitch_deg(double planet_radius_km, double altitude_km) {
    const double r = planet_radius_km + std::max(altitude_km, 0.0);
    const double dip_deg = std::acos(std::min(1.0, planet_radius_km / r)) / kDeg;
    return std::max(-90.0, 5.0 - 1.5 * dip_deg);
}

Image render_sky_gl(const SkyModel& tables, const NeuralSky* net, const SkyRenderSettings& s,
                    const PlanetRenderOptions& options) {
    sky::make_render_hd(tables, s); // the CPU renderer's checks of the settings
    const PlanetView v = planet_view_from_settings(tables.atmosphere(), s);
    PlanetRenderOptions o = options;
    o.sun_disc = s.sun_disc;
    o.published_ground = s.published_ground;
    PlanetRenderer r(tables, net, o);
    return r.render(v);
}

} // namespace skybake
