// RAII wrappers, shader programs and float render targets.
#include <fmt/format.h>

#include "gl/gl.h"
#include "skybake/error.h"

namespace skybake::gl {

void delete_buffer(GLuint id) {
    glDeleteBuffers(1, &id);
}
void delete_texture(GLuint id) {
    glDeleteTextures(1, &id);
}
void delete_framebuffer(GLuint id) {
    glDeleteFramebuffers(1, &id);
}
void delete_renderbuffer(GLuint id) {
    glDeleteRenderbuffers(1, &id);
}
void delete_vertex_array(GLuint id) {
    glDeleteVertexArrays(1, &id);
}
void delete_program(GLuint id) {
    glDeleteProgram(id);
}

Buffer make_buffer() {
    GLuint id = 0;
    glGenBuffers(1, &id);
    return Buffer(id);
}
Texture make_texture() {
    GLuint id = 0;
    glGenTextures(1, &id);
    return Texture(id);
}
VertexArray make_vertex_array() {
    GLuint id = 0;
    glGenVertexArrays(1, &id);
    return VertexArray(id);
}

void check_gl(const char* what) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR)
        throw Error(fmt::format("OpenGL error 0x{:x} in {}", e, what), "OpenGL");
}

namespace {

std::string first_line(std::string log) {
    while (!log.empty() && (log.back() == '\n' || log.back() == '\r' || log.back() == ' '))
        log.pop_back();
    const std::size_t nl = log.find('\n');
    return nl == std::string::npos ? log : log.substr(0, nl);
}

const char* stage_name(GLenum stage) {
    switch (stage) {
    case GL_VERTEX_SHADER: return "vertex";
    case GL_GEOMETRY_SHADER: return "geometry";
    case GL_FRAGMENT_SHADER: return "fragment";
    case GL_COMPUTE_SHADER: return "compute";
    default: return "unknown";
    }
}

GLuint compile(GLenum stage, const ShaderSource& src, const std::string& name) {
    std::vector<const char*> ptrs;
    for (const std::string& p : src.pieces)
        ptrs.push_back(p.c_str());
    const GLuint s = glCreateShader(stage);
    glShaderSource(s, GLsizei(ptrs.size()), ptrs.data(), nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
        std::string log(std::size_t(len > 0 ? len : 1), '\0');
        glGetShaderInfoLog(s, GLsizei(log.size()), nullptr, log.data());
        glDeleteShader(s);
        log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
        throw Error(fmt::format("{} shader does not compile: {}", stage_name(stage), first_line(log)),
                    name + " shader");
    }
    return s;
}

} // namespace

Program link_program(const std::string& name, const std::vector<ShaderStage>& stages) {
    std::vector<GLuint> shaders;
    try {
        for (const ShaderStage& st : stages)
            shaders.push_back(compile(st.stage, st.source, name));
    } catch (...) {
        for (GLuint s : shaders)
            glDeleteShader(s);
        throw;
    }
    Program p(glCreateProgram());
    for (GLuint s : shaders)
        glAttachShader(p.get(), s);
    glLinkProgram(p.get());
    for (GLuint s : shaders)
        glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(p.get(), GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(p.get(), GL_INFO_LOG_LENGTH, &len);
        std::string log(std::size_t(len > 0 ? len : 1), '\0');
        glGetProgramInfoLog(p.get(), GLsizei(log.size()), nullptr, log.data());
        log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
        throw Error("program does not link: " + first_line(log), name + " shader");
    }
    return p;
}

Program link_program(const std::string& name, const ShaderSource& vertex, const ShaderSource& fragment) {
    return link_program(name, {{GL_VERTEX_SHADER, vertex}, {GL_FRAGMENT_SHADER, fragment}});
}

RenderTarget::RenderTarget(int width, int height) : width_(width), height_(height) {
    GLuint id = 0;
    glGenFramebuffers(1, &id);
    fbo_ = Framebuffer(id);
    colour_ = make_texture();
    glBindTexture(GL_TEXTURE_2D, colour_.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenRenderbuffers(1, &id);
    depth_ = Renderbuffer(id);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour_.get(), 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw Error(fmt::format("a {}x{} RGBA32F framebuffer is not complete (status 0x{:x})", width, height, status),
                    "OpenGL");
    check_gl("render target");
}

void RenderTarget::bind() const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glViewport(0, 0, width_, height_);
}

std::vector<float> RenderTarget::read_rgba() const {
    std::vector<float> px(std::size_t(width_) * std::size_t(height_) * 4);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, px.data());
    check_gl("readback");
    return px;
}

Image RenderTarget::read_rgb() const {
    const std::vector<float> px = read_rgba();
    Image img(width_, height_);
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
            const float* s = px.data() + (std::size_t(height_ - 1 - y) * std::size_t(width_) + std::size_t(x)) * 4;
            float* d = img.pixel(x, y);
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
        }
    return img;
}

} // namespace skybake::gl
