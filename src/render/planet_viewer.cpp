// Interactive planet viewer (`skybake view planet`): the planet renderer in
// the window shell (window_shell.h) shared with `skybake view MODEL`.
// Controls: drag with the left mouse button to look around; W/S forward and
// back, A/D sideways, R/F up and down, with a speed proportional to the
// altitude (Shift: ×10); arrow keys move the sun (left/right azimuth, up/down
// elevation); V toggles per-vertex and per-pixel shading; +/- exposure; P
// writes a screenshot; Esc quits. The Dear ImGui panel holds the sun, the
// exposure and the shading rate; the overlay the altitude, fps and triangles.
#if defined(SKYBAKE_HAS_WINDOW)

#include <chrono>
#include <cmath>

#include "render/planet_scene.h" // epoxy's GL before GLFW's
#include "render/window_shell.h"
#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <imgui.h>

#include "skybake/error.h"
#include "skybake/viewer.h"

namespace skybake {

using namespace render;

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;
} // namespace

void run_planet_viewer(const SkyModel& tables, const NeuralSky* net, const ViewerOptions& o) {
    WindowShell shell(o.width, o.height, "skybake planet", o.frames);
    PlanetRenderOptions ro[2] = {o.render, o.render};
    ro[0].shading = ShadingRate::Vertex;
    ro[1].shading = ShadingRate::Pixel;
    int mode = o.render.shading == ShadingRate::Pixel ? 1 : 0;
    std::unique_ptr<PlanetScene> scenes[2];
    scenes[mode] = std::make_unique<PlanetScene>(shell, tables, net, ro[mode]);
    const double R = tables.atmosphere().planet_radius_km;
    glm::dvec3 eye(0.0, 0.0, R + o.altitude_km);
    // Degrees; from high up the default pitch looks down at the planet.
    double yaw = o.yaw_deg,
           pitch = std::isnan(o.pitch_deg) ? planet_viewer_default_pitch_deg(R, o.altitude_km) : o.pitch_deg;
    float sun_el = float(o.sun_elevation_deg), sun_az = float(o.sun_azimuth_deg);
    float exposure = float(o.exposure_ev);
    bool need_auto_exposure = o.auto_exposure; // set from the first frame, as `skybake view MODEL`
    std::unique_ptr<RenderTarget> target;
    while (shell.begin_frame()) {
        const double dt = shell.seconds_per_frame();
        // Mouse look.
        double dx, dy;
        shell.drag(dx, dy);
        yaw -= dx * 0.004 / kDeg;
        pitch = std::clamp(pitch - dy * 0.004 / kDeg, -90.0, 90.0);
        const double alt = glm::length(eye) - R;
        const PlanetView cam = planet_viewer_view(eye, yaw, pitch, sun_az, sun_el, 1, 1);
        const glm::dvec3 up = glm::normalize(eye), fwd = cam.forward;
        const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
        // Flight, speed proportional to the altitude.
        const double speed = std::max(alt, 0.002) * (shell.key_down(GLFW_KEY_LEFT_SHIFT) ? 10.0 : 1.0);
        glm::dvec3 move(0.0);
        auto key = [&](int k) { return shell.key_down(k); };
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
            sun_az -= float(30.0 * dt);
        if (key(GLFW_KEY_RIGHT))
            sun_az += float(30.0 * dt);
        if (key(GLFW_KEY_UP))
            sun_el = std::min(90.0f, sun_el + float(10.0 * dt));
        if (key(GLFW_KEY_DOWN))
            sun_el = std::max(-90.0f, sun_el - float(10.0 * dt));
        if (key(GLFW_KEY_EQUAL) || key(GLFW_KEY_KP_ADD))
            exposure += float(2.0 * dt);
        if (key(GLFW_KEY_MINUS) || key(GLFW_KEY_KP_SUBTRACT))
            exposure -= float(2.0 * dt);
        bool toggle = shell.key_pressed(GLFW_KEY_V);
        const bool screenshot = shell.key_pressed(GLFW_KEY_P);

        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::Begin("skybake planet", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
        ImGui::SliderFloat("sun elevation", &sun_el, -90.0f, 90.0f, "%.1f deg");
        ImGui::SliderFloat("sun azimuth", &sun_az, -180.0f, 180.0f, "%.1f deg");
        ImGui::SliderFloat("exposure", &exposure, -16.0f, 16.0f, "%+.1f EV");
        ImGui::SameLine();
        if (ImGui::Button("auto"))
            need_auto_exposure = true;
        int rate = mode;
        if (ImGui::Combo("shading", &rate, "per vertex\0per pixel\0") && rate != mode)
            toggle = true;
        ImGui::End();
        if (toggle) {
            mode ^= 1;
            if (!scenes[mode])
                scenes[mode] = std::make_unique<PlanetScene>(shell, tables, net, ro[mode]);
        }

        const int w = shell.framebuffer_width(), h = shell.framebuffer_height();
        if (w < 1 || h < 1) {
            shell.end_frame();
            continue;
        }
        if (!target || target->width() != w || target->height() != h)
            target = std::make_unique<RenderTarget>(w, h);
        // The sun in the local frame of the starting point (the pole), as in `sky render`.
        const PlanetView view = planet_viewer_view(eye, yaw, pitch, sun_az, sun_el, w, h);
        PlanetFrameStats st;
        target->bind();
        scenes[mode]->update_mesh(view, &st);
        scenes[mode]->draw(view, false, &st);
        if (need_auto_exposure) {
            exposure = model_auto_exposure_ev(target->read_rgb());
            need_auto_exposure = false;
        }
        if (screenshot) {
            save_screenshot(o.screenshot, target->read_rgb(), exposure);
            fmt::print(stderr, "wrote {}\n", o.screenshot);
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        scenes[mode]->tone_map(target->colour_texture(), w, h, exposure, ToneCurve::Aces);
        shell.overlay({fmt::format("{:.1f} fps", shell.fps()), fmt::format("altitude {:.3f} km", alt),
                       fmt::format("{} triangles, per-{}", st.triangles, mode ? "pixel" : "vertex")});
        shell.end_frame();
    }
    target.reset();
    scenes[0].reset();
    scenes[1].reset();
}

} // namespace skybake

#endif // SKYBAKE_HAS_WINDOW
