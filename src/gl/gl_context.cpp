// Headless OpenGL contexts with EGL: Mesa's surfaceless platform
// (EGL_MESA_platform_surfaceless, software llvmpipe or a GPU driver), else
// the device platform (EGL_EXT_device_enumeration + EGL_EXT_platform_device,
// as NVIDIA's EGL provides). No window and no display server; rendering goes
// to framebuffer objects.
//
// A context never terminates its display. An EGL display is one per platform
// (or device) in a process, shared by every context on it: eglTerminate from
// one context's destructor would release the others' too. And Mesa 22.3's
// llvmpipe keeps about 8 KiB each time a display that has drawn is terminated
// and initialised again, so a process that creates a context per bake grew
// without end (tests/soak_slow_test.cpp). eglInitialize of an initialised
// display does nothing, so every context after the first reuses it.
#include <cstdlib>
#include <cstring>
#include <string>

#include <epoxy/egl.h>
#include <fmt/format.h>

#include "gl/gl.h"
#include "skybake/error.h"

namespace skybake::gl {

namespace {

constexpr const char* kWhere = "OpenGL";

std::string egl_error_name(EGLint e) {
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return fmt::format("EGL error 0x{:x}", e);
    }
}

bool has_extension(const char* list, const char* name) {
    if (!list)
        return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return true;
    return false;
}

class EglContext final : public GlContext {
public:
    explicit EglContext(GlApi api) {
        es_ = api == GlApi::Es3;
        const char* env = std::getenv("SKYBAKE_EGL_PLATFORM");
        const std::string platform = env && *env ? env : "auto";
        if (platform != "auto" && platform != "surfaceless" && platform != "device" && platform != "none")
            throw Error(fmt::format("SKYBAKE_EGL_PLATFORM is '{}'; use auto, surfaceless, device or none", platform),
                        kWhere);
        const char* client = platform == "none" ? nullptr : eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        std::string tried;
        if ((platform == "auto" || platform == "surfaceless") &&
            has_extension(client, "EGL_MESA_platform_surfaceless")) {
            display_ = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            if (!try_initialize())
                tried += "surfaceless: " + egl_error_name(eglGetError()) + "; ";
        }
        if (display_ == EGL_NO_DISPLAY && (platform == "auto" || platform == "device") &&
            has_extension(client, "EGL_EXT_device_enumeration") && has_extension(client, "EGL_EXT_platform_device")) {
            EGLDeviceEXT devices[16];
            EGLint count = 0;
            if (eglQueryDevicesEXT(16, devices, &count))
                for (EGLint i = 0; i < count && display_ == EGL_NO_DISPLAY; ++i) {
                    display_ = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                    if (!try_initialize())
                        tried += fmt::format("device {}: {}; ", i, egl_error_name(eglGetError()));
                }
        }
        if (display_ == EGL_NO_DISPLAY)
            throw Error("no headless OpenGL found: EGL offers neither the surfaceless nor a device platform (" +
                            (tried.empty() ? std::string("no such EGL extension") : tried.substr(0, tried.size() - 2)) +
                            "); install libegl-mesa0 and libgl1-mesa-dri, or an NVIDIA driver with EGL",
                        kWhere);
        if (!eglBindAPI(es_ ? EGL_OPENGL_ES_API : EGL_OPENGL_API))
            fail(es_ ? "EGL cannot bind the OpenGL ES API" : "EGL cannot bind the desktop OpenGL API");
        const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, es_ ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_BIT,
                                         EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint n = 0;
        if (!eglChooseConfig(display_, config_attribs, &config, 1, &n) || n < 1) {
            if (!has_extension(eglQueryString(display_, EGL_EXTENSIONS), "EGL_KHR_no_config_context"))
                fail(es_ ? "EGL has no configuration for OpenGL ES 3" : "EGL has no configuration for desktop OpenGL");
            config = EGL_NO_CONFIG_KHR;
        }
        const EGLint desktop_attribs[] = {
            EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        const EGLint es_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
        context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, es_ ? es_attribs : desktop_attribs);
        if (context_ == EGL_NO_CONTEXT)
            fail(es_ ? "cannot create an OpenGL ES 3.0 context with EGL"
                     : "cannot create an OpenGL 3.3 core context with EGL");
        make_current();
        if (es_)
            check_es_version(kWhere);
        else
            check_version(kWhere);
    }
    ~EglContext() override {
        if (display_ != EGL_NO_DISPLAY) {
            if (eglGetCurrentContext() == context_) // another context that is current stays current
                eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            if (context_ != EGL_NO_CONTEXT)
                eglDestroyContext(display_, context_);
            // The display stays initialised for the rest of the process (see
            // the note at the top): it is shared by every context on it.
        }
    }
    void make_current() override {
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            fail("cannot make the EGL context current (EGL_KHR_surfaceless_context missing?)");
    }

private:
    bool try_initialize() {
        if (display_ == EGL_NO_DISPLAY)
            return false;
        EGLint major = 0, minor = 0;
        if (eglInitialize(display_, &major, &minor))
            return true;
        display_ = EGL_NO_DISPLAY;
        return false;
    }
    [[noreturn]] void fail(const std::string& what) {
        const EGLint e = eglGetError();
        if (context_ != EGL_NO_CONTEXT)
            eglDestroyContext(display_, context_);
        display_ = EGL_NO_DISPLAY;
        throw Error(fmt::format("{} ({})", what, egl_error_name(e)), kWhere);
    }
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
};

} // namespace

std::string GlContext::description() const {
    const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return fmt::format("{}, {}", v ? v : "?", r ? r : "?");
}

void GlContext::check_version(const std::string& where) {
    const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    if (!v)
        throw Error("the OpenGL context reports no version", where);
    if (std::strncmp(v, "OpenGL ES", 9) == 0)
        throw Error(fmt::format("the context is {}; desktop OpenGL 3.3 core or newer is needed", v), where);
    if (std::sscanf(v, "%d.%d", &major_, &minor_) != 2)
        throw Error(fmt::format("cannot read the OpenGL version '{}'", v), where);
    if (major_ * 10 + minor_ < 33)
        throw Error(fmt::format("OpenGL {}.{} found; desktop OpenGL 3.3 core or newer is needed (driver: {})", major_,
                                minor_, description()),
                    where);
    clip_control_ = epoxy_gl_version() >= 45 || epoxy_has_gl_extension("GL_ARB_clip_control");
}

void GlContext::check_es_version(const std::string& where) {
    const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    if (!v)
        throw Error("the OpenGL ES context reports no version", where);
    if (std::sscanf(v, "OpenGL ES %d.%d", &major_, &minor_) != 2)
        throw Error(fmt::format("the context is '{}', not OpenGL ES", v), where);
    if (major_ < 3)
        throw Error(fmt::format("OpenGL ES {}.{} found; 3.0 or newer is needed (driver: {})", major_, minor_,
                                description()),
                    where);
    es_ = true;
}

std::unique_ptr<GlContext> create_headless_context(GlApi api) {
    return std::make_unique<EglContext>(api);
}

} // namespace skybake::gl
