// The window shell shared by `skybake view MODEL` and `skybake view planet`:
// a GLFW window with an OpenGL 3.3 core context, Dear ImGui on it (its GLFW
// and OpenGL 3 backends), an overlay of frame statistics, an orbit camera, a
// tone-mapping pass from a linear float texture and PNG screenshots.
//
// Only compiled when the build has a window (SKYBAKE_HAS_WINDOW: GLFW and
// Dear ImGui were found); src/render/window_unavailable.cpp stands in
// otherwise.
//
// [SECTION] Window
// [SECTION] Orbit camera
// [SECTION] Tone mapping and screenshots
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "gl/gl.h" // epoxy's GL before GLFW's
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "skybake/image.h"
#include "skybake/image_io.h"

namespace skybake::render {

// [SECTION] Window ---------------------------------------------------------------------------

// Throws skybake::Error (where: "display") when no display can be opened or
// no OpenGL 3.3 core context created. frame_limit > 0: the window closes
// itself after that many frames (tests), and does not wait for vertical sync.
class WindowShell final : public gl::GlContext {
public:
    WindowShell(int width, int height, const std::string& title, int frame_limit = 0);
    ~WindowShell() override;
    WindowShell(const WindowShell&) = delete;
    WindowShell& operator=(const WindowShell&) = delete;

    void make_current() override;
    GLFWwindow* window() const { return window_; }

    // Polls events and starts an ImGui frame; false when the window should
    // close (closed, Esc, or the frame limit reached): then draw nothing more.
    // Throws skybake::Interrupted once SIGINT or SIGTERM was recorded
    // (skybake/interrupt.h), so that a signal ends the window at the next frame.
    bool begin_frame();
    // Draws ImGui over the frame and swaps buffers. capture: also writes what
    // the window shows (the panel included) to this PNG before the swap.
    void end_frame(const std::filesystem::path& capture = {});

    int framebuffer_width() const { return fb_width_; }
    int framebuffer_height() const { return fb_height_; }
    double seconds_per_frame() const { return dt_; } // of the last frame, clamped to 0.25 s
    double fps() const { return fps_; }              // smoothed
    int frames_drawn() const { return frames_; }
    // A key went down since the last frame, and ImGui does not want the keyboard.
    bool key_pressed(int glfw_key) const;
    // A key is held, and ImGui does not want the keyboard.
    bool key_down(int glfw_key) const;
    // Dragging with the left button outside the panel: the mouse's motion in pixels, else (0, 0).
    void drag(double& dx, double& dy) const;
    // Mouse wheel steps outside the panel this frame.
    float wheel() const;
    // The overlay in the top-right corner: one line each.
    void overlay(const std::vector<std::string>& lines) const;

private:
    GLFWwindow* window_ = nullptr;
    int frame_limit_ = 0, frames_ = 0, fb_width_ = 0, fb_height_ = 0;
    double dt_ = 0.0, fps_ = 0.0, last_time_ = 0.0;
    bool imgui_glfw_ = false, imgui_gl_ = false;
    std::vector<char> was_down_, pressed_;
};

// [SECTION] Orbit camera ---------------------------------------------------------------------

// Left drag orbits (azimuth, elevation, degrees), the wheel zooms (distance
// factor); reset() goes back to where it started.
struct OrbitCamera {
    float azimuth_deg = 35.0f, elevation_deg = 30.0f, zoom = 1.0f;
    float start_azimuth_deg = 35.0f, start_elevation_deg = 30.0f, start_zoom = 1.0f;
    void start(float azimuth, float elevation, float zoom_factor);
    void update(const WindowShell& shell);
    void reset();
};

// [SECTION] Tone mapping and screenshots ----------------------------------------------------------

// Draws a linear RGBA32F texture (width × height, GL order) into the bound
// framebuffer, times 2^exposure_ev, ACES and sRGB as save_image() does.
class ToneMapper {
public:
    ToneMapper(); // needs a current context
    void draw(unsigned texture, int width, int height, float exposure_ev) const;

private:
    gl::Program program_;
    gl::VertexArray vao_;
};

// Writes a tone-mapped PNG (ACES at exposure_ev) through a temporary file
// beside it, renamed when complete. Throws skybake::Error as save_image().
void save_screenshot(const std::filesystem::path& path, const Image& linear, float exposure_ev);

} // namespace skybake::render
