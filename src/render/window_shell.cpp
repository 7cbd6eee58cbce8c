// The window shell: GLFW, Dear ImGui (Cornut, https://github.com/ocornut/imgui,
// its backends/imgui_impl_glfw and imgui_impl_opengl3) and the pieces both
// viewers share. See window_shell.h.
#if defined(SKYBAKE_HAS_WINDOW)

#include "render/window_shell.h"

#include <algorithm>
#include <cmath>
#include <system_error>

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>

#include "render/shaders.h"
#include "skybake/error.h"
#include "skybake/interrupt.h"
#include "skybake/image_io.h"

namespace skybake::render {

namespace {
void ignore_imgui_message(void*, const char*, ...) {}
} // namespace

WindowShell::WindowShell(int width, int height, const std::string& title, int frame_limit) : frame_limit_(frame_limit) {
    glfwSetErrorCallback([](int, const char*) {});
    if (!glfwInit())
        throw Error("cannot open a window: no display (set DISPLAY or WAYLAND_DISPLAY, or render headless with "
                    "--screenshot)",
                    "display");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw Error("cannot create an OpenGL 3.3 core window on this display", "display");
    }
    make_current();
    glfwSwapInterval(frame_limit_ > 0 ? 0 : 1);
    try {
        check_version("display");
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr; // no imgui.ini beside the user's files
        ImGui::StyleColorsDark();
        imgui_glfw_ = ImGui_ImplGlfw_InitForOpenGL(window_, true);
        imgui_gl_ = imgui_glfw_ && ImGui_ImplOpenGL3_Init("#version 330 core");
        if (!imgui_gl_)
            throw Error("Dear ImGui cannot start on this OpenGL context", "display");
    } catch (...) {
        if (imgui_glfw_)
            ImGui_ImplGlfw_Shutdown();
        if (ImGui::GetCurrentContext())
            ImGui::DestroyContext();
        glfwDestroyWindow(window_);
        glfwTerminate();
        throw;
    }
    was_down_.assign(GLFW_KEY_LAST + 1, 0);
    pressed_.assign(GLFW_KEY_LAST + 1, 0);
    last_time_ = glfwGetTime();
}

WindowShell::~WindowShell() {
    make_current();
    // An error thrown in the middle of a frame (while the panel was built): close the frame first.
    if (ImGuiContext* c = ImGui::GetCurrentContext(); c && c->WithinFrameScope) {
        ImGui::ErrorCheckEndFrameRecover(ignore_imgui_message); // the missing End() calls
        ImGui::EndFrame();
    }
    if (imgui_gl_)
        ImGui_ImplOpenGL3_Shutdown();
    if (imgui_glfw_)
        ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window_);
    glfwTerminate();
}

void WindowShell::make_current() {
    glfwMakeContextCurrent(window_);
}

bool WindowShell::begin_frame() {
    check_interrupted(); // SIGINT or SIGTERM (recorded by the CLI's handlers) ends the window with 128 + N
    if (frame_limit_ > 0 && frames_ >= frame_limit_)
        return false;
    glfwPollEvents();
    if (glfwWindowShouldClose(window_))
        return false;
    const double now = glfwGetTime();
    dt_ = std::clamp(now - last_time_, 1e-6, 0.25);
    last_time_ = now;
    fps_ = fps_ == 0.0 ? 1.0 / dt_ : 0.9 * fps_ + 0.1 / dt_;
    for (int k = GLFW_KEY_SPACE; k <= GLFW_KEY_LAST; ++k) {
        const bool down = glfwGetKey(window_, k) == GLFW_PRESS;
        pressed_[std::size_t(k)] = down && !was_down_[std::size_t(k)];
        was_down_[std::size_t(k)] = down;
    }
    glfwGetFramebufferSize(window_, &fb_width_, &fb_height_);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (key_pressed(GLFW_KEY_ESCAPE)) {
        ImGui::EndFrame();
        return false;
    }
    return true;
}

void WindowShell::end_frame(const std::filesystem::path& capture) {
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fb_width_, fb_height_);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (!capture.empty() && fb_width_ > 0 && fb_height_ > 0) {
        // The back buffer holds sRGB values: back to linear, written with the identity tone map.
        std::vector<unsigned char> rgb(std::size_t(fb_width_) * std::size_t(fb_height_) * 3);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, fb_width_, fb_height_, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
        Image img(fb_width_, fb_height_);
        for (int y = 0; y < fb_height_; ++y)
            for (int x = 0; x < fb_width_; ++x)
                for (int c = 0; c < 3; ++c)
                    img.pixel(x, fb_height_ - 1 - y)[c] = srgb_to_linear(
                        float(rgb[(std::size_t(y) * std::size_t(fb_width_) + std::size_t(x)) * 3 + std::size_t(c)]) /
                        255.0f);
        std::filesystem::path tmp = capture;
        tmp.replace_extension(".partial.png");
        save_image(tmp, img, ToneMap{0.0f, ToneCurve::Clamp});
        std::error_code ec;
        std::filesystem::rename(tmp, capture, ec);
        if (ec)
            throw Error("cannot write " + capture.string() + "; check the folder is writable", "screenshot");
    }
    glfwSwapBuffers(window_);
    ++frames_;
}

bool WindowShell::key_pressed(int key) const {
    return key >= 0 && key <= GLFW_KEY_LAST && pressed_[std::size_t(key)] && !ImGui::GetIO().WantCaptureKeyboard;
}

bool WindowShell::key_down(int key) const {
    return key >= 0 && key <= GLFW_KEY_LAST && was_down_[std::size_t(key)] && !ImGui::GetIO().WantCaptureKeyboard;
}

void WindowShell::drag(double& dx, double& dy) const {
    const ImGuiIO& io = ImGui::GetIO();
    dx = dy = 0.0;
    if (!io.WantCaptureMouse && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        dx = io.MouseDelta.x;
        dy = io.MouseDelta.y;
    }
}

float WindowShell::wheel() const {
    const ImGuiIO& io = ImGui::GetIO();
    return io.WantCaptureMouse ? 0.0f : io.MouseWheel;
}

void WindowShell::overlay(const std::vector<std::string>& lines) const {
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x + vp->WorkSize.x - 10.0f, vp->WorkPos.y + 10.0f), ImGuiCond_Always,
                            ImVec2(1.0f, 0.0f));
    ImGui::SetNextWindowBgAlpha(0.45f);
    const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                   ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;
    if (ImGui::Begin("##overlay", nullptr, flags))
        for (const std::string& l : lines)
            ImGui::TextUnformatted(l.c_str());
    ImGui::End();
}

void OrbitCamera::start(float azimuth, float elevation, float zoom_factor) {
    azimuth_deg = start_azimuth_deg = azimuth;
    elevation_deg = start_elevation_deg = elevation;
    zoom = start_zoom = zoom_factor;
}

void OrbitCamera::update(const WindowShell& shell) {
    double dx, dy;
    shell.drag(dx, dy);
    azimuth_deg = float(std::remainder(double(azimuth_deg) - 0.3 * dx, 360.0));
    elevation_deg = std::clamp(float(double(elevation_deg) + 0.3 * dy), -89.0f, 89.0f);
    if (const float w = shell.wheel(); w != 0.0f)
        zoom = std::clamp(zoom * std::pow(0.9f, w), 0.05f, 20.0f);
    if (shell.key_pressed(GLFW_KEY_R))
        reset();
}

void OrbitCamera::reset() {
    azimuth_deg = start_azimuth_deg;
    elevation_deg = start_elevation_deg;
    zoom = start_zoom;
}

ToneMapper::ToneMapper() {
    auto stage = [](const char* name) {
        gl::ShaderSource s;
        s.pieces = {"#version 330 core\n", std::string("#define ") + name + "\n", shaders::shared_source,
                    shaders::tone_curve, shaders::screen_stages};
        return s;
    };
    program_ = gl::link_program("tone", stage("SKYBAKE_STAGE_FULL_SCREEN_VS"), stage("SKYBAKE_STAGE_TONE_FS"));
    vao_ = gl::make_vertex_array();
}

void ToneMapper::draw(unsigned texture, int width, int height, float exposure_ev) const {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glViewport(0, 0, width, height);
    const GLuint p = program_.get();
    glUseProgram(p);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, texture);
    glUniform1i(glGetUniformLocation(p, "u_image"), 0);
    glUniform1f(glGetUniformLocation(p, "u_exposure_scale"), std::exp2(exposure_ev));
    glUniform1i(glGetUniformLocation(p, "u_tone"), int(ToneCurve::Aces));
    glUniform2i(glGetUniformLocation(p, "u_offset"), 0, 0);
    glBindVertexArray(vao_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
}

void save_screenshot(const std::filesystem::path& path, const Image& linear, float exposure_ev) {
    std::filesystem::path tmp = path;
    tmp.replace_extension(".partial.png");
    save_image(tmp, linear, ToneMap{exposure_ev, ToneCurve::Aces});
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw Error("cannot write the screenshot " + path.string() + "; check the folder is writable", "screenshot");
    }
}

} // namespace skybake::render

#endif // SKYBAKE_HAS_WINDOW
