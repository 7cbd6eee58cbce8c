// The raster visibility backend: depth cube maps per vertex, or depth maps per
// direction, in an OpenGL 4.3 context (raster_tracer.h; the views and the
// bias are documented in shaders/raster_visibility.glsl and docs/baking.md).
#include "visibility/raster/raster_tracer.h"

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <cstdlib>
#include <future>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "core/parallel.h"
#include "gl/gl.h"
#include "skybake/error.h"
#include "skybake/interrupt.h"
#include "skybake/mesh.h"
#include "visibility/raster/shaders.h"
#include "visibility/trace_hd.h"

namespace skybake {

std::uint32_t raster_cube_resolution(std::size_t rule_points) {
    const double spacing = std::sqrt(4.0 * M_PI / double(std::max<std::size_t>(rule_points, 1)));
    const double texels = 0.5 * M_PI / spacing; // a texel no wider than the spacing at the face's centre
    return std::clamp<std::uint32_t>(8 * std::uint32_t(std::ceil(texels / 8.0)), 16, 256);
}

} // namespace skybake

namespace skybake::visibility {

namespace {

// GPU (or llvmpipe) memory for the depth layers of one draw.
constexpr std::uint64_t kDepthBytes = std::uint64_t(256) << 20;
// GPU memory for one chunk's bits and vertex records.
constexpr std::uint64_t kChunkBytes = std::uint64_t(256) << 20;
// The near plane of the cube faces, as a fraction of the far plane. It must
// lie closer than any surface a ray can meet: the driver's step off a vertex
// is only 2^-15 of its coordinates (bake::rounding_step()), so near the world
// origin a blocker that touches the vertex (a wall at the foot of which a
// ground vertex lies) is a few 1e-6 of the scene away, and a near plane at
// 1e-6 of the far one clipped it away: those vertices read open. The depth
// is near / distance along the face's axis (reversed z, cube_projection()),
// which a float keeps to 2^-24 relative at any distance, and x and y do not
// depend on the near plane, so a tiny one costs no precision; 2^-40 keeps
// it positive and finite in float for any far plane the batch can have.
constexpr float kNearFraction = 0x1p-40f;
constexpr int kFaces = 5;
// Triangles per cluster of the cube method's binning.
constexpr std::size_t kClusterTriangles = 64;

// The cube's faces as frusta in the vertex's frame (t, b, n): a point x
// (relative to the ray origin) is inside face f when dot(x, P) ≥ 0 for its
// four inward plane normals P. Face 0 looks along n; faces 1 to 4 along +t,
// −t, +b, −b, their upper halves (x·n ≥ 0).
struct CubeFrusta {
    glm::vec3 p[kFaces][4];
    float length[kFaces][4];
};

CubeFrusta cube_frusta(const glm::vec3& t, const glm::vec3& b, const glm::vec3& n) {
    CubeFrusta f{{{n - t, n + t, n - b, n + b},
                  {t - b, t + b, t - n, n},
                  {-t - b, -t + b, -t - n, n},
                  {b - t, b + t, b - n, n},
                  {-b - t, -b + t, -b - n, n}},
                 {}};
    for (int i = 0; i < kFaces; ++i)
        for (int k = 0; k < 4; ++k)
            f.length[i][k] = glm::length(f.p[i][k]);
    return f;
}

// A cube face's projection: a 90° square frustum with reversed z and no far
// plane: clip z = near and clip w = d, the distance along the face's axis,
// so that with GL_ZERO_TO_ONE clipping the depth is near / d in (0, 1],
// nearer is greater, and the clipper keeps d ≥ near. The fragment shader
// then writes nothing (llvmpipe tests depth early and runs no shader), and
// the compute pass recovers d per texel. The side faces are whole squares
// too: their lower halves (below the horizon) are drawn but never read.
glm::mat4 cube_projection(float near) {
    glm::mat4 m = glm::frustum(-near, near, -near, near, near, 2.0f * near); // x, y and w rows
    m[0][2] = 0.0f, m[1][2] = 0.0f, m[2][2] = 0.0f, m[3][2] = near;
    return m;
}

// Whether a triangle may cover a texel centre of a cube face of
// resolution² texels (w, u and v: three values each): GL draws only the fragments whose centre the triangle
// contains (OpenGL 4.6, section 14.6.1). Its corners k are given in the
// face's terms: distance w[k] along the face's axis and (u[k], v[k]) across
// it, so that they project to (u, v) / w in [−1, 1]². Every face is a full
// 90° square (the side faces' lower halves are drawn but never read), so
// the texel grid is the same under the square's symmetries and the
// orientation of (u, v) does not matter. Far parts of a mesh are mostly
// triangles that cover no centre at the resolutions the rules need. Kept
// when a corner is not in front of the eye (the clipper decides), and
// within a margin of 1/64 texel, far above the rasteriser's snapping of
// vertices to 1/256.
bool may_cover_a_centre(const float* w, const float* u, const float* v, float resolution) {
    constexpr float margin = 1.0f / 64.0f;
    glm::vec2 p[3];
    glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (int k = 0; k < 3; ++k) {
        if (!(w[k] > 0.0f))
            return true;
        p[k] = (glm::vec2(u[k], v[k]) / w[k] * 0.5f + 0.5f) * resolution;
        lo = glm::min(lo, p[k]);
        hi = glm::max(hi, p[k]);
    }
    // The centres i + 1/2 in [lo − margin, hi + margin].
    const glm::vec2 first = glm::ceil(lo - margin - 0.5f), last = glm::floor(hi + margin - 0.5f);
    if (first.x > last.x || first.y > last.y)
        return false;
    if ((last.x - first.x) + (last.y - first.y) > 2.0f)
        return true; // more than a few centres: not worth testing one by one
    // A few centres: is one of them inside the triangle, each edge moved out
    // by the margin?
    const float area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    if (!(std::abs(area) > 1e-12f))
        return true; // degenerate in window space: left to the rasteriser
    const float sign = area > 0.0f ? 1.0f : -1.0f;
    for (float y = first.y; y <= last.y; y += 1.0f)
        for (float x = first.x; x <= last.x; x += 1.0f) {
            const glm::vec2 c(x + 0.5f, y + 0.5f);
            bool inside = true;
            for (int k = 0; k < 3 && inside; ++k) {
                const glm::vec2 e = p[(k + 1) % 3] - p[k];
                inside = sign * (e.x * (c.y - p[k].y) - e.y * (c.x - p[k].x)) >= -margin * glm::length(e);
            }
            if (inside)
                return true;
        }
    return false;
}

// Appends to faces[f] (kFaces lists) the numbers of the mesh's triangles
// that may cover face f of the hemicube at `origin`. A triangle is left out
// only when its three corners lie outside one plane of the face's frustum by
// more than a relative margin of 1e-5, far above rounding, so that every
// triangle the rasteriser could draw is kept (touching ones included). A
// cluster's bounding sphere decides for all its triangles when it lies
// wholly outside a plane, or wholly inside the frustum, or beyond t_max (the
// rule's maximum distance) from the origin. Of the rest, those that cover no
// texel centre of the face (may_cover_a_centre()) are left out, unless
// resolution is 0.
void bin_cube_faces(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                    const std::vector<glm::vec4>& clusters, const glm::vec3& origin, const glm::vec3& t,
                    const glm::vec3& b, const glm::vec3& n, const CubeFrusta& f, float t_max, float resolution,
                    std::vector<std::uint32_t>* faces) {
    const std::size_t triangles = indices.size() / 3;
    for (std::size_t c = 0; c < clusters.size(); ++c) {
        const glm::vec3 centre = glm::vec3(clusters[c]) - origin;
        const float r = clusters[c].w;
        if (glm::length(centre) - r > t_max * 1.00001f)
            continue; // beyond the maximum distance: no ray may meet it
        const std::size_t first = c * kClusterTriangles, last = std::min(triangles, first + kClusterTriangles);
        // Per face: 0 out, 1 partly in (test each triangle), 2 wholly in.
        int state[kFaces];
        bool any = false;
        for (int face = 0; face < kFaces; ++face) {
            bool out = false, inside = true;
            for (int k = 0; k < 4 && !out; ++k) {
                const float d = glm::dot(centre, f.p[face][k]), reach = r * f.length[face][k];
                out = d < -reach * 1.00001f;
                inside = inside && d > reach * 1.00001f;
            }
            state[face] = out ? 0 : inside ? 2 : 1;
            any = any || state[face] != 0;
        }
        if (!any)
            continue;
        for (std::size_t tri = first; tri < last; ++tri) {
            // The corners in the vertex's frame (a along t, e along b, h along
            // n): every plane of the five frusta is a sum of two of them.
            float a[3], e[3], h[3], m[3];
            bool below = true;
            for (int k = 0; k < 3; ++k) {
                const glm::vec3 x = positions[indices[3 * tri + std::size_t(k)]] - origin;
                a[k] = glm::dot(x, t), e[k] = glm::dot(x, b), h[k] = glm::dot(x, n);
                m[k] = 1e-5f * (std::abs(x.x) + std::abs(x.y) + std::abs(x.z));
                below = below && h[k] < -m[k];
            }
            if (below)
                continue; // under the horizon: no face sees it
            // Outside the plane of value v(x) when all three corners are below −margin.
            const auto outside = [&](float sa, float se, float sh) {
                return sa * a[0] + se * e[0] + sh * h[0] < -m[0] && sa * a[1] + se * e[1] + sh * h[1] < -m[1] &&
                       sa * a[2] + se * e[2] + sh * h[2] < -m[2];
            };
            const auto keep = [&](int face) {
                switch (face) {
                case 0: return !(outside(-1, 0, 1) || outside(1, 0, 1) || outside(0, -1, 1) || outside(0, 1, 1));
                case 1: return !(outside(1, -1, 0) || outside(1, 1, 0) || outside(1, 0, -1));
                case 2: return !(outside(-1, -1, 0) || outside(-1, 1, 0) || outside(-1, 0, -1));
                case 3: return !(outside(-1, 1, 0) || outside(1, 1, 0) || outside(0, 1, -1));
                default: return !(outside(-1, -1, 0) || outside(1, -1, 0) || outside(0, -1, -1));
                }
            };
            // Each face's axis and the two across it (cube_frusta()'s order).
            const float na[3] = {-a[0], -a[1], -a[2]}, ne[3] = {-e[0], -e[1], -e[2]};
            const float* axis[kFaces] = {h, a, na, e, ne};
            const float* across[kFaces][2] = {{a, e}, {e, h}, {e, h}, {a, h}, {a, h}};
            for (int face = 0; face < kFaces; ++face)
                if ((state[face] == 2 || (state[face] == 1 && keep(face))) &&
                    (resolution == 0.0f || may_cover_a_centre(axis[face], across[face][0], across[face][1], resolution)))
                    faces[face].push_back(std::uint32_t(tri));
        }
    }
}

// Traces `rays` and sets bit which[q] of `words` where ray q is blocked.
void trace_into(const RayQueries& queries, const std::vector<Ray>& rays, const std::vector<std::uint32_t>& which,
                std::vector<std::uint8_t>& hit, std::uint32_t* words) {
    hit.resize(rays.size());
    queries.occluded(rays, hit);
    for (std::size_t q = 0; q < rays.size(); ++q)
        if (hit[q])
            set_bit(words, which[q]);
}

// glMultiDrawElementsIndirect's command (OpenGL 4.6, section 10.4).
struct DrawElementsCommand {
    GLuint count, instance_count, first_index;
    GLint base_vertex;
    GLuint base_instance;
};

// The std430 layout of `Vertex` in raster_visibility.glsl.
struct GpuVertex {
    glm::vec4 origin, t, b, n, r0, r1, r2;
};
static_assert(sizeof(GpuVertex) == 112);

// An orthonormal frame (t, b, n) around a unit n (Duff et al., JCGT 2017).
void frame_of(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
    const float s = std::copysign(1.0f, n.z);
    const float a = -1.0f / (s + n.z);
    const float c = n.x * n.y * a;
    t = glm::vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}

gl::Buffer storage_buffer(std::size_t bytes) {
    gl::Buffer b = gl::make_buffer();
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b.get());
    glBufferData(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(std::max<std::size_t>(bytes, 16)), nullptr, GL_DYNAMIC_DRAW);
    return b;
}

template <class T>
void upload(const gl::Buffer& b, const std::vector<T>& data) {
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b.get());
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(data.size() * sizeof(T)), data.data());
}

GLint uniform(GLuint program, const char* name) {
    return glGetUniformLocation(program, name);
}

// At least `invocations` invocations of the 64-wide compute shader, as a 2D
// grid when one row would pass the 65,535 groups every GL 4.3 has.
void dispatch(std::uint64_t invocations) {
    const std::uint64_t groups = (invocations + 63) / 64;
    if (groups == 0)
        return;
    const std::uint64_t x = std::min<std::uint64_t>(groups, 65535);
    glDispatchCompute(GLuint(x), GLuint((groups + x - 1) / x), 1);
}

} // namespace

struct RasterTracer::State {
    std::unique_ptr<gl::GlContext> context; // first: destroyed last
    BackFaces back_faces = BackFaces::Occlude;
    bool have_programs = false;
    gl::Program draw, bits;
    gl::VertexArray vao;
    gl::Buffer positions, indices;
    GLsizei index_count = 0;
    // Cube: the mesh on the CPU, in clusters of consecutive triangles with
    // their bounding spheres, for binning each face's triangles
    // (bin_cube_faces()); the binned indices, one draw command per layer
    // (its baseInstance picks the layer through the a_layer attribute).
    std::vector<glm::vec3> mesh_positions;
    std::vector<std::uint32_t> mesh_indices;
    std::vector<glm::vec4> clusters; // xyz centre, w radius
    gl::VertexArray cube_vao;
    gl::Buffer layer_ids, cube_indices, commands;
    glm::vec3 centre{0.0f};
    float radius = 0.0f;
    bool have_mesh = false;

    TraceRule rule;
    std::vector<glm::vec4> points;
    std::uint32_t batch = 0;  // cube: vertices per draw; directional: directions per draw
    std::uint32_t layers = 0; // of the depth array
    gl::Buffer views, eyes, point_buffer, vertex_buffer, word_buffer;
    std::size_t vertex_capacity = 0, word_capacity = 0;
    gl::Texture depth;
    gl::Framebuffer fbo;
    GLint max_layers = 0, max_size = 0;
    std::uint32_t depth_resolution = 0; // of the depth array
    // The vertex shader writes gl_Layer (GL_ARB_shader_viewport_layer_array:
    // Mesa, NVIDIA); else a geometry shader does. SKYBAKE_RASTER_GEOMETRY_SHADER=1
    // forces the geometry shader (tests of that path).
    bool vs_layer = false;
    // Cube: leave out the triangles that cover no texel centre (bin_cube_faces).
    // SKYBAKE_RASTER_DRAW_ALL=1 keeps them (tests that the bits are the same).
    bool centre_test = true;

    // The CPU tracer's own structure of the same mesh: the rays of the
    // directional near field (answer_near_field) and of the cube's edges
    // (answer_edges); and the directional maps' last texel.
    std::unique_ptr<RayQueries> near;
    float texel = 0.0f;
    std::size_t edge_offset = 0;
};

RasterTracer::RasterTracer(TraceMethod method, std::uint32_t resolution)
    : method_(method), resolution_(resolution), s_(std::make_unique<State>()) {
    if (method != TraceMethod::Cube && method != TraceMethod::Directional)
        throw Error(
            fmt::format("the raster backend has the methods cube and directional, not {}", trace_method_name(method)),
            "method");
    if (resolution_ == 0 && method == TraceMethod::Directional)
        resolution_ = kRasterDirectionalResolution;
    // The cube's default comes with the rule (set_rule(): raster_cube_resolution()).
    auto_resolution_ = resolution_ == 0;
    if (!auto_resolution_ && (resolution_ < 8 || resolution_ > kRasterMaxResolution))
        throw Error(fmt::format("resolution must be 8 to {} texels; got {}", kRasterMaxResolution, resolution_),
                    "resolution");
    try {
        s_->context = gl::create_headless_context();
    } catch (const Error& e) {
        throw Error("the raster backend needs OpenGL: " + e.message(), "backend");
    }
    if (!s_->context->at_least(4, 3))
        throw Error(fmt::format("the raster backend needs OpenGL 4.3 (compute shaders, storage buffers); the context "
                                "is {}",
                                s_->context->description()),
                    "backend");
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &s_->max_layers);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &s_->max_size);
    const char* draw_all = std::getenv("SKYBAKE_RASTER_DRAW_ALL");
    s_->centre_test = !(draw_all && *draw_all == '1');
    const char* force_gs = std::getenv("SKYBAKE_RASTER_GEOMETRY_SHADER");
    s_->vs_layer = epoxy_has_gl_extension("GL_ARB_shader_viewport_layer_array") && !(force_gs && *force_gs == '1');
    if (GLint(resolution_) > s_->max_size)
        throw Error(
            fmt::format("resolution {} is more than this OpenGL's texture limit, {}", resolution_, s_->max_size),
            "resolution");
    if (method_ == TraceMethod::Cube && s_->max_layers < kFaces)
        throw Error("this OpenGL has too few texture array layers for a hemicube", "backend");
    if (!s_->context->at_least(4, 5) && !epoxy_has_gl_extension("GL_ARB_clip_control"))
        throw Error(fmt::format("the raster backend needs OpenGL 4.5 or GL_ARB_clip_control (reversed depth); the "
                                "context is {}",
                                s_->context->description()),
                    "backend");
    s_->vao = gl::make_vertex_array();
    s_->views = storage_buffer(0);
    s_->eyes = storage_buffer(0);
    s_->point_buffer = storage_buffer(0);
    s_->vertex_buffer = storage_buffer(0);
    s_->word_buffer = storage_buffer(0);
    gl::check_gl("raster backend setup");
}

RasterTracer::~RasterTracer() {
    if (s_ && s_->context) {
        s_->context->make_current(); // the GL names are deleted with their context current
        State* s = s_.get();
        s->draw.reset();
        s->bits.reset();
        s->vao.reset();
        s->cube_vao.reset();
        s->layer_ids.reset();
        s->cube_indices.reset();
        s->commands.reset();
        s->positions.reset();
        s->indices.reset();
        s->views.reset();
        s->eyes.reset();
        s->point_buffer.reset();
        s->vertex_buffer.reset();
        s->word_buffer.reset();
        s->depth.reset();
        s->fbo.reset();
    }
}

std::string RasterTracer::device_name() const {
    s_->context->make_current();
    const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return r ? r : "OpenGL";
}

void RasterTracer::build_programs() {
    const std::string head =
        std::string("#version 430 core\n") +
        (method_ == TraceMethod::Cube ? "#define SKYBAKE_CUBE\n" : "#define SKYBAKE_DIRECTIONAL\n") +
        (s_->back_faces == BackFaces::Ignore ? "#define SKYBAKE_IGNORE_BACK_FACES\n" : "");
    auto stage = [&](const char* define) {
        const bool vs_layer = s_->vs_layer && std::string(define) == "SKYBAKE_STAGE_VS";
        return gl::ShaderSource{{head,
                                 vs_layer ? "#extension GL_ARB_shader_viewport_layer_array : require\n"
                                            "#define SKYBAKE_VS_LAYER\n"
                                          : "",
                                 std::string("#define ") + define + "\n", raster::shaders::raster_visibility}};
    };
    if (s_->vs_layer)
        s_->draw = gl::link_program("raster visibility", {{GL_VERTEX_SHADER, stage("SKYBAKE_STAGE_VS")},
                                                          {GL_FRAGMENT_SHADER, stage("SKYBAKE_STAGE_FS")}});
    else
        s_->draw = gl::link_program("raster visibility", {{GL_VERTEX_SHADER, stage("SKYBAKE_STAGE_VS")},
                                                          {GL_GEOMETRY_SHADER, stage("SKYBAKE_STAGE_GS")},
                                                          {GL_FRAGMENT_SHADER, stage("SKYBAKE_STAGE_FS")}});
    s_->bits = gl::link_program("raster bits", {{GL_COMPUTE_SHADER, stage("SKYBAKE_STAGE_CS")}});
    s_->have_programs = true;
}

void RasterTracer::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    validate_mesh(mesh, "mesh");
    s_->context->make_current();
    if (!s_->have_programs || back_faces != s_->back_faces) {
        s_->back_faces = back_faces;
        build_programs();
    }
    if (mesh.triangle_count() > std::size_t(std::numeric_limits<GLsizei>::max() / 3))
        throw Error(fmt::format("{} triangles is too many for one OpenGL draw", mesh.triangle_count()), "mesh");
    glBindVertexArray(s_->vao.get());
    s_->positions = gl::make_buffer();
    glBindBuffer(GL_ARRAY_BUFFER, s_->positions.get());
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.positions.size() * sizeof(glm::vec3)), mesh.positions.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    s_->indices = gl::make_buffer();
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s_->indices.get());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(std::uint32_t)), mesh.indices.data(),
                 GL_STATIC_DRAW);
    s_->index_count = GLsizei(mesh.indices.size());
    glBindVertexArray(0);
    if (method_ == TraceMethod::Cube)
        set_cube_mesh(mesh);
    const Bounds bounds = compute_bounds(mesh);
    s_->centre = 0.5f * (bounds.min + bounds.max);
    s_->radius = std::max(0.5f * glm::length(bounds.extent()), 1e-30f);
    if (!s_->near)
        s_->near = make_ray_queries(std::string(kNearFieldTracer));
    s_->near->set_mesh(mesh, back_faces);
    s_->have_mesh = true;
    gl::check_gl("raster backend mesh upload");
}

// The cube method's copy of the mesh: clusters of kClusterTriangles
// consecutive triangles (meshes keep neighbours together) with a bounding
// sphere each, and the vertex array of the binned draws.
void RasterTracer::set_cube_mesh(const Mesh& mesh) {
    State& s = *s_;
    s.mesh_positions = mesh.positions;
    s.mesh_indices = mesh.indices;
    const std::size_t triangles = mesh.triangle_count();
    s.clusters.clear();
    for (std::size_t first = 0; first < triangles; first += kClusterTriangles) {
        const std::size_t last = std::min(triangles, first + kClusterTriangles);
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (std::size_t i = 3 * first; i < 3 * last; ++i) {
            lo = glm::min(lo, mesh.positions[mesh.indices[i]]);
            hi = glm::max(hi, mesh.positions[mesh.indices[i]]);
        }
        const glm::vec3 c = 0.5f * (lo + hi);
        float r = 0.0f;
        for (std::size_t i = 3 * first; i < 3 * last; ++i)
            r = std::max(r, glm::length(mesh.positions[mesh.indices[i]] - c));
        s.clusters.emplace_back(c, r * 1.0001f + 1e-30f);
    }
    s.cube_vao = gl::make_vertex_array();
    glBindVertexArray(s.cube_vao.get());
    glBindBuffer(GL_ARRAY_BUFFER, s.positions.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    // Layer ids 0, 1, 2, ...: with divisor 1 a draw's baseInstance selects one.
    std::vector<std::int32_t> ids(std::size_t(std::max(s.max_layers, kFaces)));
    for (std::size_t i = 0; i < ids.size(); ++i)
        ids[i] = std::int32_t(i);
    s.layer_ids = gl::make_buffer();
    glBindBuffer(GL_ARRAY_BUFFER, s.layer_ids.get());
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(ids.size() * sizeof(std::int32_t)), ids.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(1);
    glVertexAttribIPointer(1, 1, GL_INT, sizeof(std::int32_t), nullptr);
    glVertexAttribDivisor(1, 1);
    s.cube_indices = gl::make_buffer();
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s.cube_indices.get());
    glBindVertexArray(0);
    s.commands = gl::make_buffer();
}

std::uint32_t RasterTracer::set_rule(const TraceRule& rule) {
    if (!s_->have_mesh)
        throw Error("set_mesh() must come before set_rule()", "mesh");
    const auto k = std::uint32_t(rule.points.size());
    if (method_ == TraceMethod::Directional) {
        if (rule.rotate)
            throw Error("the directional method draws one depth map per rule direction, so every vertex must share "
                        "them: use a rule without +rotate, or the cube method",
                        "rule");
        if (std::isfinite(rule.t_max))
            throw Error("the directional method sees the whole mesh along each direction, so it has no maximum "
                        "distance: leave it unlimited, or use the cube method",
                        "max_distance");
    }
    s_->context->make_current();
    if (auto_resolution_)
        resolution_ = raster_cube_resolution(k);
    s_->rule = rule;
    s_->points.resize(k);
    for (std::uint32_t j = 0; j < k; ++j)
        s_->points[j] = glm::vec4(rule.points[j], 0.0f);
    s_->point_buffer = storage_buffer(s_->points.size() * sizeof(glm::vec4));
    upload(s_->point_buffer, s_->points);

    const std::uint64_t layer_bytes = std::uint64_t(resolution_) * resolution_ * 4;
    std::uint32_t layers;
    if (method_ == TraceMethod::Cube) {
        s_->batch = std::uint32_t(
            std::clamp<std::uint64_t>(kDepthBytes / (kFaces * layer_bytes), 1, std::uint64_t(s_->max_layers / kFaces)));
        layers = s_->batch * kFaces;
    } else {
        s_->batch = std::uint32_t(
            std::clamp<std::uint64_t>(kDepthBytes / layer_bytes, 1, std::min<std::uint64_t>(s_->max_layers, k)));
        s_->batch = std::max<std::uint32_t>(s_->batch, 1);
        layers = s_->batch;
    }
    if (layers != s_->layers || resolution_ != s_->depth_resolution || !s_->depth) {
        s_->layers = layers;
        s_->depth_resolution = resolution_;
        s_->depth = gl::make_texture();
        glBindTexture(GL_TEXTURE_2D_ARRAY, s_->depth.get());
        glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_DEPTH_COMPONENT32F, GLsizei(resolution_), GLsizei(resolution_),
                       GLsizei(layers));
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_NONE);
        GLuint id = 0;
        glGenFramebuffers(1, &id);
        s_->fbo = gl::Framebuffer(id);
        glBindFramebuffer(GL_FRAMEBUFFER, id);
        glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, s_->depth.get(), 0); // layered
        glDrawBuffer(GL_NONE);
        glReadBuffer(GL_NONE);
        const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (status != GL_FRAMEBUFFER_COMPLETE)
            throw Error(fmt::format("a {0}x{0}x{1} depth texture array is not a complete framebuffer (status 0x{2:x})",
                                    resolution_, layers, status),
                        "backend");
        s_->views = storage_buffer(layers * sizeof(glm::mat4));
        s_->eyes = storage_buffer(layers * sizeof(glm::vec4));
    }
    gl::check_gl("raster backend rule setup");
    const std::uint64_t per_vertex = 4ull * rule.words_per_vertex + sizeof(GpuVertex);
    return std::uint32_t(std::clamp<std::uint64_t>(kChunkBytes / per_vertex, 1, 0xffffffffu));
}

namespace {

// Binds the draw state shared by both methods: the depth array as the target,
// depth test LESS, the mesh, the per-layer buffers. `cull` is the face that
// rays pass through (GL_FRONT, GL_BACK), or GL_NONE.
// reversed: the cube's reversed z (cube_projection()): depth in [0, 1] from
// clip z / w, cleared to 0, nearer is greater.
void begin_draw(GLuint fbo, std::uint32_t resolution, GLuint program, GLuint vao, GLuint views, GLuint eyes,
                GLenum cull, bool reversed) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, GLsizei(resolution), GLsizei(resolution));
    glEnable(GL_DEPTH_TEST);
    glClipControl(GL_LOWER_LEFT, reversed ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    glDepthFunc(reversed ? GL_GREATER : GL_LESS);
    glDepthMask(GL_TRUE);
    if (cull == GL_NONE) {
        glDisable(GL_CULL_FACE);
    } else {
        glEnable(GL_CULL_FACE);
        glFrontFace(GL_CCW);
        glCullFace(cull);
    }
    glDisable(GL_BLEND);
    glClearDepth(reversed ? 0.0 : 1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glUseProgram(program);
    glBindVertexArray(vao);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, views);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, eyes);
}

} // namespace

void RasterTracer::trace(const TraceChunk& chunk) {
    if (!s_->have_mesh || s_->layers == 0)
        throw Error("set_mesh() and set_rule() must come before trace()", "rule");
    if (chunk.count == 0)
        return;
    s_->context->make_current();
    const std::size_t words = std::size_t(chunk.count) * s_->rule.words_per_vertex;
    // The blocked words, then as many "edge" words (answer_edges, answer_near_field).
    const std::size_t stored = 2 * words;
    if (stored > s_->word_capacity) {
        s_->word_buffer = storage_buffer(stored * 4);
        s_->word_capacity = stored;
    }
    s_->edge_offset = words;
    if (method_ == TraceMethod::Cube)
        trace_cube(chunk);
    else
        trace_directional(chunk);

    // The blocked bits, in visiting order, become V in rule order: set where
    // the direction is on or above the horizon (the same test as every other
    // backend) and nothing was drawn closer than the maximum distance.
    std::vector<std::uint32_t> blocked(stored);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, s_->word_buffer.get());
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(stored * 4), blocked.data());
    gl::check_gl("raster backend read-back");
    if (method_ == TraceMethod::Directional)
        answer_near_field(chunk, blocked);
    else
        answer_edges(chunk, blocked);
    const TraceRule& rule = s_->rule;
    const auto k = std::uint32_t(rule.points.size());
    parallel_for(chunk.count, 256, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const glm::mat3 r = rule.rotate ? chunk.rotations[i] : glm::mat3(1.0f);
            const std::uint32_t* mine = blocked.data() + i * rule.words_per_vertex;
            std::uint32_t* out = chunk.words.data() + i * rule.words_per_vertex;
            std::fill(out, out + rule.words_per_vertex, 0u);
            for (std::uint32_t j = 0; j < k; ++j) {
                glm::vec3 x;
                float c;
                vertex_direction(rule.points[j], r, rule.rotate, chunk.normals[i], x, c);
                if (needs_ray(c) && !get_bit(mine, j))
                    set_bit(out, rule.order[j]);
            }
        }
    });
}

// The directional maps answer a ray from a point kLookupTexels texels off its
// origin (along the driver's offset direction), with the depth of the four
// texels around it. Within kNearFieldTexels texels of the ray that answer is
// not to be trusted, and rays of the CPU tracer (kNearFieldTracer, its own
// structure of the same mesh) give it instead:
//   - open: a blocker nearer the origin than the look-up point, along the ray,
//     is behind the point (a thin part, a crevice): each direction the maps
//     left open is traced up to kNearFieldTexels texels;
//   - blocked by something near: a blocker within kNearFieldTexels texels of
//     the look-up point may be beside the ray rather than on it (a ledge, a
//     surface seen at a grazing angle, a texel's worth of blur): the direction
//     is traced whole;
//   - edges: where the four texels disagree, a blocker's edge passes within a
//     texel or two of the ray: traced whole;
//   - contacts: a surface that crosses the segment from the origin to the
//     look-up point puts the point inside or behind it, where every map reads
//     blocked: the vertex is traced whole.
// The compute pass flags the second and third cases as "edge" bits.
// blocked: the read-back words in visiting order, the blocked words and then
// (from s_->edge_offset) the edge words.
void RasterTracer::answer_near_field(const TraceChunk& chunk, std::vector<std::uint32_t>& blocked) {
    const TraceRule& rule = s_->rule;
    const auto k = std::uint32_t(rule.points.size());
    const std::uint32_t wpv = rule.words_per_vertex;
    const float lookup = kLookupTexels * s_->texel, reach = kNearFieldTexels * s_->texel;
    const RayQueries& near = *s_->near;
    parallel_for(chunk.count, 16, [&](std::size_t b, std::size_t e) {
        std::vector<Ray> rays;
        std::vector<std::uint8_t> hit;
        std::vector<std::uint32_t> which;
        for (std::size_t i = b; i < e; ++i) {
            const glm::vec3 o = chunk.origins[i], n = chunk.normals[i];
            const glm::vec3 t = chunk.offsets.empty() ? n : chunk.offsets[i];
            Ray segment;
            segment.origin = o;
            segment.direction = t;
            segment.t_max = lookup;
            std::uint8_t contact = 0;
            near.occluded({&segment, 1}, {&contact, 1});
            std::uint32_t* mine = blocked.data() + i * wpv;
            const std::uint32_t* edge = blocked.data() + s_->edge_offset + i * wpv;
            rays.clear();
            which.clear();
            for (std::uint32_t j = 0; j < k; ++j) {
                glm::vec3 x;
                float c;
                vertex_direction(rule.points[j], glm::mat3(1.0f), false, n, x, c);
                if (!needs_ray(c))
                    continue;
                const bool whole = contact || get_bit(edge, j);
                if (!whole && get_bit(mine, j))
                    continue; // the maps saw a blocker beyond the near field
                if (whole)
                    mine[j / 32] &= ~(1u << (j % 32)); // the ray's answer replaces the maps'
                Ray r;
                r.origin = o;
                r.direction = x;
                r.t_max = whole ? rule.t_max : reach;
                rays.push_back(r);
                which.push_back(j);
            }
            trace_into(near, rays, which, hit, mine);
        }
    });
}

// Cube: a texel's centre stands for every direction in it, which puts a
// blocker's edge up to a texel off. Where the four texels around a direction
// disagree, or the direction is within half a texel of its face's border
// (the compute pass's "edge" bits), a ray of the CPU tracer
// (kNearFieldTracer, its own structure of the same mesh) answers instead.
void RasterTracer::answer_edges(const TraceChunk& chunk, std::vector<std::uint32_t>& blocked) {
    const TraceRule& rule = s_->rule;
    const auto k = std::uint32_t(rule.points.size());
    const std::uint32_t wpv = rule.words_per_vertex;
    const RayQueries& near = *s_->near;
    std::vector<std::size_t> counts(chunk.count, 0);
    parallel_for(chunk.count, 16, [&](std::size_t b, std::size_t e) {
        std::vector<Ray> rays;
        std::vector<std::uint8_t> hit;
        std::vector<std::uint32_t> which;
        for (std::size_t i = b; i < e; ++i) {
            const glm::mat3 r = rule.rotate ? chunk.rotations[i] : glm::mat3(1.0f);
            std::uint32_t* mine = blocked.data() + i * wpv;
            const std::uint32_t* edge = blocked.data() + s_->edge_offset + i * wpv;
            rays.clear();
            which.clear();
            for (std::uint32_t j = 0; j < k; ++j) {
                if (!get_bit(edge, j))
                    continue;
                glm::vec3 x;
                float c;
                vertex_direction(rule.points[j], r, rule.rotate, chunk.normals[i], x, c);
                if (!needs_ray(c))
                    continue;
                mine[j / 32] &= ~(1u << (j % 32)); // the ray's answer replaces the texel's
                Ray ray;
                ray.origin = chunk.origins[i];
                ray.direction = x;
                ray.t_max = rule.t_max;
                rays.push_back(ray);
                which.push_back(j);
            }
            trace_into(near, rays, which, hit, mine);
            counts[i] = rays.size();
        }
    });
    for (std::size_t c : counts)
        edge_rays_ += c;
}

// The compute pass of both methods: the depth layers just drawn become the
// "blocked" words of pass.count vertices (raster_visibility.glsl, stage CS).
void RasterTracer::run_bits(const BitsPass& pass) {
    const State& s = *s_;
    const TraceRule& rule = s.rule;
    const GLuint p = s.bits.get();
    glUseProgram(p);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, s.depth.get());
    glUniform1i(uniform(p, "u_depth"), 0);
    glUniform1i(uniform(p, "u_count"), GLint(pass.count));
    glUniform1i(uniform(p, "u_first"), GLint(pass.first));
    glUniform1i(uniform(p, "u_words_per_vertex"), GLint(rule.words_per_vertex));
    glUniform1i(uniform(p, "u_first_word"), GLint(pass.first_word));
    glUniform1i(uniform(p, "u_word_count"), GLint(pass.word_count));
    glUniform1i(uniform(p, "u_first_point"), GLint(pass.first_point));
    glUniform1i(uniform(p, "u_last_point"), GLint(pass.last_point));
    glUniform1i(uniform(p, "u_rotate"), rule.rotate ? 1 : 0);
    glUniform1i(uniform(p, "u_resolution"), GLint(resolution_));
    glUniform1f(uniform(p, "u_far"), pass.far);
    glUniform1f(uniform(p, "u_t_max"), std::isfinite(rule.t_max) ? rule.t_max : 3.0e38f);
    glUniform1f(uniform(p, "u_lookup"), kLookupTexels * pass.texel);
    glUniform1i(uniform(p, "u_edge_offset"), GLint(s.edge_offset));
    glUniform1f(uniform(p, "u_recheck"), kNearFieldTexels * pass.texel);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s.views.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s.point_buffer.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s.vertex_buffer.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s.word_buffer.get());
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT); // a word may take a second batch of directions
    dispatch(std::uint64_t(pass.count) * pass.word_count);
}

// Cube: one batch of vertices, as the CPU prepares it (trace_cube).
struct CubeBatch {
    std::uint32_t first = 0, count = 0;
    float near = 0.0f;
    std::vector<glm::mat4> views; // per layer
    std::vector<glm::vec4> eyes;  // per layer
    std::vector<GpuVertex> vertices;
    std::vector<std::vector<std::uint32_t>> lists; // per layer: the triangles binned to it
    std::vector<std::uint32_t> indices;            // the layers' triangles, 16-bit pairs where short_indices
    std::vector<DrawElementsCommand> commands;
    std::size_t triangles = 0;
    bool short_indices = false;
};

// Batches are drawn while the CPU bins the next one: llvmpipe's front end
// keeps one core busy during a draw, and binning the next batch takes the
// other.
void RasterTracer::trace_cube(const TraceChunk& chunk) {
    State& s = *s_;
    const TraceRule& rule = s.rule;
    const std::uint32_t wpv = rule.words_per_vertex;
    if (s.batch > s.vertex_capacity) {
        s.vertex_buffer = storage_buffer(s.batch * sizeof(GpuVertex));
        s.vertex_capacity = s.batch;
    }
    const float resolution = s.centre_test ? float(resolution_) : 0.0f; // 0: no texel-centre test
    // CPU only (it runs beside the GL calls of the batch before).
    const auto prepare = [&s, &rule, &chunk, resolution](std::uint32_t first, CubeBatch& c) {
        const std::uint32_t count = std::min(s.batch, chunk.count - first);
        c.first = first;
        c.count = count;
        // One far plane for the batch: past every point of the mesh from every
        // origin in it (and no further than needed for a maximum distance).
        // The depth does not use it (reversed z has none): it sets the near one.
        float far = 0.0f;
        for (std::uint32_t i = 0; i < count; ++i)
            far = std::max(far, glm::length(chunk.origins[first + i] - s.centre) + s.radius);
        far *= 1.001f;
        if (std::isfinite(rule.t_max))
            far = std::min(far, rule.t_max * 1.001f);
        far = std::max(far, 1e-30f);
        c.near = std::max(far * kNearFraction, std::numeric_limits<float>::min());
        const glm::mat4 face = cube_projection(c.near);
        c.views.resize(std::size_t(count) * kFaces);
        c.eyes.resize(c.views.size());
        c.vertices.resize(count);
        for (std::uint32_t i = 0; i < count; ++i) {
            const glm::vec3 o = chunk.origins[first + i], n = chunk.normals[first + i];
            glm::vec3 t, b;
            frame_of(n, t, b);
            const glm::vec3 zero(0.0f);
            glm::mat4* v = &c.views[std::size_t(i) * kFaces];
            v[0] = face * glm::lookAt(zero, n, b);
            v[1] = face * glm::lookAt(zero, t, n);
            v[2] = face * glm::lookAt(zero, -t, n);
            v[3] = face * glm::lookAt(zero, b, n);
            v[4] = face * glm::lookAt(zero, -b, n);
            for (int f = 0; f < kFaces; ++f)
                c.eyes[std::size_t(i) * kFaces + f] = glm::vec4(o, 1.0f);
            GpuVertex& g = c.vertices[i];
            g.origin = glm::vec4(o, 1.0f);
            g.t = glm::vec4(t, 0.0f);
            g.b = glm::vec4(b, 0.0f);
            g.n = glm::vec4(n, 0.0f);
            const glm::mat3 r = rule.rotate ? chunk.rotations[first + i] : glm::mat3(1.0f);
            g.r0 = glm::vec4(r[0], 0.0f);
            g.r1 = glm::vec4(r[1], 0.0f);
            g.r2 = glm::vec4(r[2], 0.0f);
        }

        // Each layer draws only the triangles that may cover it (a vertex sees
        // a hemisphere, and a triangle mostly falls in one or two of its five
        // faces, and far ones cover no texel centre): the rasteriser, whose
        // cost is per triangle on llvmpipe, then sets up a small part of
        // vertices × 5 × triangles.
        c.lists.resize(std::size_t(count) * kFaces); // kept from batch to batch: no allocation once grown
        for (std::vector<std::uint32_t>& l : c.lists)
            l.clear();
        parallel_for(count, 4, [&](std::size_t lb, std::size_t le) {
            for (std::size_t i = lb; i < le; ++i) {
                const GpuVertex& g = c.vertices[i];
                const glm::vec3 t(g.t), b(g.b), n(g.n);
                bin_cube_faces(s.mesh_positions, s.mesh_indices, s.clusters, glm::vec3(g.origin), t, b, n,
                               cube_frusta(t, b, n), rule.t_max, resolution, &c.lists[i * kFaces]);
            }
        });
        std::vector<std::size_t> at(c.lists.size() + 1, 0);
        c.commands.clear();
        for (std::size_t layer = 0; layer < c.lists.size(); ++layer) {
            if (!c.lists[layer].empty()) // an empty face stays cleared: no draw
                c.commands.push_back({GLuint(3 * c.lists[layer].size()), 1, GLuint(at[layer]), 0, GLuint(layer)});
            at[layer + 1] = at[layer] + 3 * c.lists[layer].size();
        }
        const std::size_t total = at.back();
        c.triangles = total / 3;
        // 16-bit indices where the mesh allows: half the bytes to write and upload.
        c.short_indices = s.mesh_positions.size() <= 65536;
        c.indices.resize(c.short_indices ? (total + 1) / 2 : total);
        parallel_for(c.lists.size(), 8, [&](std::size_t lb, std::size_t le) {
            for (std::size_t layer = lb; layer < le; ++layer) {
                std::size_t q = at[layer];
                for (const std::uint32_t tri : c.lists[layer]) {
                    const std::uint32_t* v = &s.mesh_indices[3 * std::size_t(tri)];
                    if (c.short_indices) {
                        auto* out = reinterpret_cast<std::uint16_t*>(c.indices.data());
                        out[q] = std::uint16_t(v[0]), out[q + 1] = std::uint16_t(v[1]), out[q + 2] = std::uint16_t(v[2]);
                    } else {
                        c.indices[q] = v[0], c.indices[q + 1] = v[1], c.indices[q + 2] = v[2];
                    }
                    q += 3;
                }
            }
        });
    };

    CubeBatch batches[2];
    prepare(0, batches[0]);
    for (std::uint32_t first = 0, k = 0; first < chunk.count; first += s.batch, k ^= 1) {
        check_interrupted();
        CubeBatch& c = batches[k];
        const std::uint32_t next = first + s.batch;
        std::future<void> ahead;
        if (next < chunk.count)
            ahead = std::async(std::launch::async, [&prepare, next, &batches, k] { prepare(next, batches[k ^ 1]); });
        try {
            upload(s.views, c.views);
            upload(s.eyes, c.eyes);
            upload(s.vertex_buffer, c.vertices);
            const std::size_t bytes = c.short_indices ? 2 * 3 * c.triangles : 4 * 3 * c.triangles;
            glBindVertexArray(s.cube_vao.get());
            glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(std::max<std::size_t>(bytes, 4)), c.indices.data(),
                         GL_STREAM_DRAW);
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, s.commands.get());
            glBufferData(GL_DRAW_INDIRECT_BUFFER, GLsizeiptr(c.commands.size() * sizeof(DrawElementsCommand)),
                         c.commands.data(), GL_STREAM_DRAW);
            drawn_triangles_ += c.triangles;

            // Rays from the origin meet a triangle from behind where the camera
            // at the origin sees its back: GL's back faces (the views do not
            // mirror).
            begin_draw(s.fbo.get(), resolution_, s.draw.get(), s.cube_vao.get(), s.views.get(), s.eyes.get(),
                       s.vs_layer && s.back_faces == BackFaces::Ignore ? GL_BACK : GL_NONE, true);
            glMultiDrawElementsIndirect(GL_TRIANGLES, c.short_indices ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT, nullptr,
                                        GLsizei(c.commands.size()), 0);
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);

            BitsPass pass;
            pass.count = c.count;
            pass.first = c.first;
            pass.first_word = 0;
            pass.word_count = wpv;
            pass.first_point = 0;
            pass.last_point = std::uint32_t(rule.points.size());
            pass.far = c.near; // the depth is near / distance along the face's axis
            run_bits(pass);
            gl::check_gl("raster backend cube pass");
        } catch (...) {
            if (ahead.valid())
                ahead.wait(); // it reads `batches` and the chunk
            throw;
        }
        if (ahead.valid())
            ahead.get(); // rethrows what binning threw
    }
}

void RasterTracer::trace_directional(const TraceChunk& chunk) {
    State& s = *s_;
    const TraceRule& rule = s.rule;
    const auto k = std::uint32_t(rule.points.size());
    if (chunk.count > s.vertex_capacity) {
        s.vertex_buffer = storage_buffer(chunk.count * sizeof(GpuVertex));
        s.vertex_capacity = chunk.count;
    }
    std::vector<GpuVertex> vertices(chunk.count);
    for (std::uint32_t i = 0; i < chunk.count; ++i) {
        GpuVertex& g = vertices[i];
        g = GpuVertex{};
        g.origin = glm::vec4(chunk.origins[i], 1.0f);
        g.n = glm::vec4(chunk.normals[i], 0.0f);
        // The direction the driver moved the origin off its point: the
        // normal, or on borders and creases the normal plus a tangent.
        g.t = glm::vec4(chunk.offsets.empty() ? chunk.normals[i] : chunk.offsets[i], 0.0f);
    }
    upload(s.vertex_buffer, vertices);
    // Every origin is inside the padded bounding sphere (origins sit a rounding
    // step off the surface, plus the user's offset).
    float r = s.radius;
    for (std::uint32_t i = 0; i < chunk.count; ++i)
        r = std::max(r, glm::length(chunk.origins[i] - s.centre));
    r *= 1.01f;
    const glm::mat4 ortho = glm::ortho(-r, r, -r, r, 0.25f * r, 2.75f * r);
    const float range = 2.5f * r, texel = 2.0f * r / float(resolution_);
    s.texel = texel;
    std::vector<glm::mat4> views(s.batch);
    std::vector<glm::vec4> eyes(s.batch);
    for (std::uint32_t j0 = 0; j0 < k; j0 += s.batch) {
        check_interrupted();
        const std::uint32_t j1 = std::min(k, j0 + s.batch);
        for (std::uint32_t j = j0; j < j1; ++j) {
            const glm::vec3 x = rule.points[j];
            const glm::vec3 up = std::abs(x.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
            views[j - j0] = ortho * glm::lookAt(s.centre + 1.5f * r * x, s.centre, up);
            eyes[j - j0] = glm::vec4(x, 0.0f);
        }
        upload(s.views, views);
        upload(s.eyes, eyes);
        // Rays along x travel towards the camera: they meet from behind the
        // triangles whose front the camera sees, GL's front faces.
        begin_draw(s.fbo.get(), resolution_, s.draw.get(), s.vao.get(), s.views.get(), s.eyes.get(),
                   s.vs_layer && s.back_faces == BackFaces::Ignore ? GL_FRONT : GL_NONE, false);
        glDrawElementsInstanced(GL_TRIANGLES, s.index_count, GL_UNSIGNED_INT, nullptr, GLsizei(j1 - j0));

        BitsPass pass;
        pass.count = chunk.count;
        pass.first = 0;
        pass.first_word = j0 / 32;
        pass.word_count = (j1 + 31) / 32 - pass.first_word;
        pass.first_point = j0;
        pass.last_point = j1;
        pass.far = range;
        pass.texel = texel;
        run_bits(pass);
        gl::check_gl("raster backend directional pass");
    }
}

} // namespace skybake::visibility

void skybake_register_raster_tracer() {
    using namespace skybake;
    TracerBackend b;
    b.name = "raster";
    b.device = "opengl";
    b.summary = "the depth buffer of any OpenGL 4.3 context (a GPU, or Mesa's llvmpipe)";
    b.methods = {TraceMethod::Cube, TraceMethod::Directional};
    b.resolution = true;
    b.make_tracer = [](TraceMethod method, std::uint32_t resolution) {
        return std::make_unique<visibility::RasterTracer>(method, resolution);
    };
    b.problem = [] {
        try {
            visibility::RasterTracer probe(TraceMethod::Cube, 0); // opens a context
            return std::string();
        } catch (const Error& e) {
            return e.message();
        }
    };
    register_tracer_backend(std::move(b));
}
