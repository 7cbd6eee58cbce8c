// The OpenGL layer: contexts, small RAII wrappers and shader programs. The
// only header of skybake that includes GL (through libepoxy, which loads the
// functions of whatever context is current), in the manner of Dear ImGui's
// backends/imgui_impl_opengl3.h.
//
// Features:
//  - a headless context: EGL on Mesa's surfaceless platform
//    (EGL_MESA_platform_surfaceless), else the EGL device platform
//    (EGL_EXT_platform_device, NVIDIA); rendering goes to framebuffer objects;
//  - a window context with GLFW (apps only);
//  - desktop OpenGL 3.3 core or newer is required; every failure (no EGL
//    display, no context, too old a version, a shader that does not compile
//    or link) throws one skybake::Error line.
//
// Environment: SKYBAKE_EGL_PLATFORM=auto (default), surfaceless, device or
// none (none finds no platform: how tests check the error path).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <epoxy/gl.h>

#include "skybake/image.h"

namespace skybake::gl {

// [SECTION] Contexts -----------------------------------------------------------

// A current OpenGL context. Destroying it releases the context.
class GlContext {
public:
    virtual ~GlContext() = default;
    virtual void make_current() = 0;
    // "4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string description() const;
    int major_version() const { return major_; }
    int minor_version() const { return minor_; }
    bool has_clip_control() const { return clip_control_; }
    // An OpenGL ES context (create_headless_context(GlApi::Es3)).
    bool is_es() const { return es_; }
    // Whether the context is at least OpenGL major.minor.
    bool at_least(int major, int minor) const { return major_ * 10 + minor_ >= major * 10 + minor; }

protected:
    // Reads and checks the version of the current context (throws below 3.3 core).
    void check_version(const std::string& where);
    // The same for an OpenGL ES context: 3.0 or newer.
    void check_es_version(const std::string& where);
    int major_ = 0, minor_ = 0;
    bool clip_control_ = false;
    bool es_ = false;
};

// Headless EGL context (no window, no display server): desktop OpenGL 3.3
// core or newer, or OpenGL ES 3.0 or newer (what WebGL 2 runs on: the tests of
// exported GLSL ES). Throws skybake::Error.
enum class GlApi { Desktop, Es3 };
std::unique_ptr<GlContext> create_headless_context(GlApi api = GlApi::Desktop);

// [SECTION] RAII wrappers -------------------------------------------------------
template <void (*Delete)(GLuint)>
class GlName {
public:
    GlName() = default;
    explicit GlName(GLuint id) : id_(id) {}
    ~GlName() { reset(); }
    GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
    GlName& operator=(GlName&& o) noexcept {
        if (this != &o) {
            reset();
            id_ = std::exchange(o.id_, 0);
        }
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;
    GLuint get() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() {
        if (id_)
            Delete(id_);
        id_ = 0;
    }

private:
    GLuint id_ = 0;
};

void delete_buffer(GLuint id);
void delete_texture(GLuint id);
void delete_framebuffer(GLuint id);
void delete_renderbuffer(GLuint id);
void delete_vertex_array(GLuint id);
void delete_program(GLuint id);

using Buffer = GlName<delete_buffer>;
using Texture = GlName<delete_texture>;
using Framebuffer = GlName<delete_framebuffer>;
using Renderbuffer = GlName<delete_renderbuffer>;
using VertexArray = GlName<delete_vertex_array>;
using Program = GlName<delete_program>;

Buffer make_buffer();
Texture make_texture();
VertexArray make_vertex_array();

// [SECTION] Shaders ------------------------------------------------------------------
// One stage's source: concatenated pieces (the #version line first).
struct ShaderSource {
    std::vector<std::string> pieces;
};
struct ShaderStage {
    GLenum stage; // GL_VERTEX_SHADER, GL_GEOMETRY_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER
    ShaderSource source;
};
// Compiles and links a program. Throws skybake::Error naming `name` with the
// stage and the first line of the info log, e.g.
//   "fragment shader does not compile: 0:12(5): error: `foo' undeclared (planet shader)".
Program link_program(const std::string& name, const std::vector<ShaderStage>& stages);
Program link_program(const std::string& name, const ShaderSource& vertex, const ShaderSource& fragment);

// [SECTION] Render targets --------------------------------------------------------------
// A framebuffer with an RGBA32F colour texture and a 32-bit float depth buffer.
class RenderTarget {
public:
    RenderTarget(int width, int height); // throws skybake::Error if incomplete
    void bind() const;
    int width() const { return width_; }
    int height() const { return height_; }
    GLuint colour_texture() const { return colour_.get(); }
    // Linear RGB of the colour attachment, top row first.
    Image read_rgb() const;
    // RGBA floats, bottom row first (GL order), 4 per pixel.
    std::vector<float> read_rgba() const;

private:
    int width_, height_;
    Framebuffer fbo_;
    Texture colour_;
    Renderbuffer depth_;
};

// Throws skybake::Error naming `what` if glGetError reports an error.
void check_gl(const char* what);

} // namespace skybake::gl
