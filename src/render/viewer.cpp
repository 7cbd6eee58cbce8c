// Interactive planet viewer: a GLFW window over the planet renderer.
// Controls: drag with the left mouse button to look around; W/S forward and
// back, A/D sideways, R/F up and down, with a speed proportional to the
// altitude (Shift: ×10); arrow keys move the sun (left/right azimuth, up/down
// elevation); V toggles per-vertex and per-pixel shading; +/- exposure; Esc
// quits. The HUD (altitude, fps, triangles, shading mode) is in the title bar.
#include <chrono>
#include <cmath>

#include "render/planet_scene.h" // epoxy's GL before GLFW's
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "sky/render_hd.h"
#include "skybake/error.h"

namespace skybake {

using namespace render;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

class GlfwContext final : public GlContext {
public:
    GlfwContext(int w, int h) {
        glfwSetErrorCallback([](int, const char*) {});
        if (!glfwInit())
            throw Error("cannot open a window: no display (set DISPLAY or WAYLAND_DISPLAY; the headless commands "
                        "sky render --renderer gl and fly need none)",
                        "display");
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
        window_ = glfwCreateWindow(w, h, "skybake planet", nullptr, nullptr);
        if (!window_) {
            glfwTerminate();
            throw Error("cannot create an OpenGL 3.3 core window", "display");
        }
        make_current();
        glfwSwapInterval(1);
        check_version("display");
    }
    ~GlfwContext() override {
        glfwDestroyWindow(window_);
        glfwTerminate();
    }
    void make_current() override { glfwMakeContextCurrent(window_); }
    GLFWwindow* window() const { return window_; }

private:
    GLFWwindow* window_ = nullptr;
};

} // namespace

void run_planet_viewer(const SkyModel& tables, const NeuralSky* net, const ViewerOptions& o) {
    GlfwContext ctx(o.width, o.height);
    GLFWwindow* win = ctx.window();
    PlanetRenderOptions ro[2] = {o.render, o.render};
    ro[0].shading = ShadingRate::Vertex;
    ro[1].shading = ShadingRate::Pixel;
    int mode = o.render.shading == ShadingRate::Pixel ? 1 : 0;
    std::unique_ptr<PlanetScene> scenes[2];
    scenes[mode] = std::make_unique<PlanetScene>(ctx, tables, net, ro[mode]);
    const double R = tables.atmosphere().planet_radius_km;
    glm::dvec3 eye(0.0, 0.0, R + o.altitude_km);
    double yaw = 0.0, pitch = 5.0 * kDeg, sun_el = o.sun_elevation_deg, sun_az = o.sun_azimuth_deg;
    float exposure = float(o.exposure_ev);
    double last_x = 0, last_y = 0;
    bool dragging = false, v_was_down = false;
    auto t_prev = std::chrono::steady_clock::now();
    double fps = 0.0;
    std::unique_ptr<RenderTarget> target;
    while (!glfwWindowShouldClose(win)) {
        glfwPollEvents();
        const auto t_now = std::chrono::steady_clock::now();
        const double dt = std::min(0.25, std::chrono::duration<double>(t_now - t_prev).count());
        t_prev = t_now;
        fps = fps == 0.0 ? 1.0 / std::max(dt, 1e-6) : 0.9 * fps + 0.1 / std::max(dt, 1e-6);
        if (glfwGetKey(win, GLFW_KEY_ESCAPE) == GLFW_PRESS)
            break;
        // Local frame at the eye: up, and a horizontal east/north basis.
        const glm::dvec3 up = glm::normalize(eye);
        glm::dvec3 east = glm::cross(glm::dvec3(0, 0, 1), up);
        east = glm::length(east) < 1e-9 ? glm::dvec3(1, 0, 0) : glm::normalize(east);
        if (glm::length(glm::cross(glm::dvec3(0, 0, 1), up)) < 1e-9)
            east = glm::dvec3(1, 0, 0);
        const glm::dvec3 north = glm::cross(up, east);
        const glm::dvec3 fwd = std::cos(pitch) * (std::cos(yaw) * east + std::sin(yaw) * north) + std::sin(pitch) * up;
        const glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
        // Mouse look.
        double mx, my;
        glfwGetCursorPos(win, &mx, &my);
        if (glfwGetMouseButton(win, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
            if (dragging) {
                yaw -= (mx - last_x) * 0.004;
                pitch = std::clamp(pitch - (my - last_y) * 0.004, -1.55, 1.55);
            }
            dragging = true;
        } else {
            dragging = false;
        }
        last_x = mx;
        last_y = my;
        // Flight, speed proportional to the altitude.
        const double alt = glm::length(eye) - R;
        double speed = std::max(alt, 0.002) * (glfwGetKey(win, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ? 10.0 : 1.0);
        glm::dvec3 move(0.0);
        auto key = [&](int k) { return glfwGetKey(win, k) == GLFW_PRESS; };
        if (key(GLFW_KEY_W))
            move += fwd;
        if (key(GLFW_KEY_S))
            move -= fwd;
        if (key(GLFW_KEY_D))
            move += right;
        if (key(GLFW_KEY_A))
            move -= right;
        if (key(GLFW_KEY_R))
            move += up;
        if (key(GLFW_KEY_F))
            move -= up;
        eye += move * speed * dt;
        if (glm::length(eye) < R + 0.001)
            eye = glm::normalize(eye) * (R + 0.001);
        if (key(GLFW_KEY_LEFT))
            sun_az -= 30.0 * dt;
        if (key(GLFW_KEY_RIGHT))
            sun_az += 30.0 * dt;
        if (key(GLFW_KEY_UP))
            sun_el = std::min(90.0, sun_el + 10.0 * dt);
        if (key(GLFW_KEY_DOWN))
            sun_el = std::max(-90.0, sun_el - 10.0 * dt);
        if (key(GLFW_KEY_EQUAL) || key(GLFW_KEY_KP_ADD))
            exposure += float(2.0 * dt);
        if (key(GLFW_KEY_MINUS) || key(GLFW_KEY_KP_SUBTRACT))
            exposure -= float(2.0 * dt);
        const bool v_down = key(GLFW_KEY_V);
        if (v_down && !v_was_down) {
            mode ^= 1;
            if (!scenes[mode])
                scenes[mode] = std::make_unique<PlanetScene>(ctx, tables, net, ro[mode]);
        }
        v_was_down = v_down;

        int w, h;
        glfwGetFramebufferSize(win, &w, &h);
        if (w < 1 || h < 1)
            continue;
        if (!target || target->width() != w || target->height() != h)
            target = std::make_unique<RenderTarget>(w, h);
        PlanetView view;
        view.eye_km = eye;
        view.forward = fwd;
        view.up = up;
        view.fov_x_deg = 90.0;
        view.width = w;
        view.height = h;
        // The sun in the local frame of the starting point (the pole), as in `sky render`.
        view.sun = glm::dvec3(sky::direction_from_angles(float(sun_az * kDeg), float(sun_el * kDeg)));
        PlanetFrameStats st;
        target->bind();
        scenes[mode]->update_mesh(view, &st);
        scenes[mode]->draw(view, false, &st);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        scenes[mode]->tone_map(target->colour_texture(), w, h, exposure, ToneCurve::Aces);
        glfwSwapBuffers(win);
        const std::string title =
            fmt::format("skybake planet | altitude {:.3f} km | {:.1f} fps | {} triangles | per-{} | sun {:.0f} deg | "
                        "exposure {:+.1f} EV",
                        alt, fps, st.triangles, mode ? "pixel" : "vertex", sun_el, exposure);
        glfwSetWindowTitle(win, title.c_str());
    }
    target.reset();
    scenes[0].reset();
    scenes[1].reset();
}

} // namespace skybake
