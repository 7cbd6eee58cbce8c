// skybake/render.h: the real-time planet renderer (OpenGL 3.3 core or newer).
// No GL types here: the GL layer stays inside src/render/.
//
// [SECTION] Options
// [SECTION] Views
// [SECTION] Headless rendering
// [SECTION] Interactive viewer
//
// The scene of seed 000 (Pietras & Rudnicki, section VII): a planet mesh
// refined by continuous level of detail (skybake/planet.h), a sky shell
// around the observer, the neural sky evaluated per vertex (the seed's mode)
// or per pixel, used for the sky and for the light scattered in front of the
// ground (N(observer) − N(probe)); the reflected ground light, the planet's
// shadow and the sun disc from the optical-length tables, uploaded as a
// texture. The network's GLSL is that of `skybake sky export` with its weights
// in a uniform block. PlanetSky::Reference runs the seed's marching sum in
// GLSL on the same tables instead. See docs/planet.md.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "skybake/image.h"
#include "skybake/neural.h"
#include "skybake/planet.h"
#include "skybake/sky.h"

namespace skybake {

// [SECTION] Options ---------------------------------------------------------------
enum class ShadingRate : int {
    Vertex = 0, // the network (or the sum) per vertex of the sky shell and the planet mesh (the seed)
    Pixel = 1,  // per pixel
};
enum class PlanetSky : int {
    Network = 0,   // the neural sky
    Reference = 1, // the seed's marching sum over the tables, in GLSL
};

struct PlanetRenderOptions {
    ShadingRate shading = ShadingRate::Vertex;
    PlanetSky sky = PlanetSky::Network;
    double max_error_px = 1.0;             // CLOD screen-space error, pixels
    std::size_t max_triangles = 2'000'000; // CLOD budget
    PlanetRelief relief;                   // amplitude 0: the smooth sphere
    // Per vertex, inside the atmosphere: a dome of view directions around the
    // eye, 3·2^level azimuths and rings of constant angle to the horizon (one
    // on it, crowding near it); level 0 to 7. Outside the atmosphere: the top
    // of the atmosphere as a mesh (the icosahedron subdivided 6 times).
    int sky_shell_level = 5;
    bool sun_disc = true;
    bool published_ground = false; // as SkyRenderSettings::published_ground
};

// [SECTION] Views -------------------------------------------------------------------
// The observer in the planet-centred frame of the CPU renderer: the observer
// of SkyRenderSettings stands at (0, 0, R0 + altitude), z up.
struct PlanetView {
    glm::dvec3 eye_km{0.0, 0.0, 6371.002}; // planet-centred, km, outside the planet
    glm::dvec3 forward{1.0, 0.0, 0.0};     // unit view direction
    glm::dvec3 up{0.0, 0.0, 1.0};          // unit, roughly up on screen (orthogonalised)
    double fov_x_deg = 90.0;               // horizontal field of view, (0, 180)
    int width = 640, height = 480;         // pixels
    glm::dvec3 sun{0.0, 0.0, 1.0};         // unit direction to the sun
};

// The camera of a SkyRenderSettings (view must be Camera): throws skybake::Error otherwise.
PlanetView planet_view_from_settings(const Atmosphere& atmosphere, const SkyRenderSettings& settings);

struct PlanetFrameStats {
    std::size_t triangles = 0;     // planet mesh
    std::size_t sky_triangles = 0; // sky shell (per-vertex) or 1 (per pixel)
    double clod_seconds = 0.0;     // mesh update and upload
    double draw_seconds = 0.0;     // drawing until the GPU finished
    double max_error_px = 0.0;
};

// [SECTION] Headless rendering ------------------------------------------------------------
// Owns a headless EGL context, the GL resources and the planet mesh; the mesh
// is kept from one render() to the next (incremental CLOD). Throws
// skybake::Error (one line) when there is no headless OpenGL, the version is
// below 3.3, a shader does not compile or the weights do not fit the driver's
// uniform block size. `net` may be null with PlanetSky::Reference.
class PlanetRenderer {
public:
    PlanetRenderer(const SkyModel& tables, const NeuralSky* net, const PlanetRenderOptions& options);
    ~PlanetRenderer();
    PlanetRenderer(const PlanetRenderer&) = delete;
    PlanetRenderer& operator=(const PlanetRenderer&) = delete;

    // Linear radiance (times the atmosphere's sun irradiance), top row first.
    Image render(const PlanetView& view, PlanetFrameStats* stats = nullptr);
    // Flat-shaded pass over the same mesh (the benchmark's baseline).
    Image render_flat(const PlanetView& view, PlanetFrameStats* stats = nullptr);
    // "4.5 (Core Profile) Mesa 22.3.6, llvmpipe (...)".
    std::string device_description() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

// `skybake sky render --renderer gl`: the camera view of settings drawn by the
// planet renderer (settings.view must be Camera; settings.method is ignored:
// the source is options.sky).
Image render_sky_gl(const SkyModel& tables, const NeuralSky* net, const SkyRenderSettings& settings,
                    const PlanetRenderOptions& options);

// [SECTION] Interactive viewer ------------------------------------------------------------------
struct ViewerOptions {
    PlanetRenderOptions render;
    int width = 1280, height = 1024;
    double altitude_km = 0.002;
    double sun_elevation_deg = 20.0, sun_azimuth_deg = 0.0;
    // The starting view (planet_viewer_view): yaw from +x towards +y, pitch
    // above the horizontal; a NaN pitch: planet_viewer_default_pitch_deg().
    double yaw_deg = 0.0, pitch_deg = std::numeric_limits<double>::quiet_NaN();
    // auto_exposure: the first frame sets the exposure (model_auto_exposure_ev,
    // as `skybake view MODEL`); else exposure_ev, stops.
    bool auto_exposure = true;
    double exposure_ev = 0.0;
    int frames = 0; // > 0: close after this many frames (tests)
    std::string screenshot = "skybake_planet.png"; // where the screenshot key (P) writes
};
// The viewer's camera at eye_km (planet-centred, km), in the local frame of
// the eye: yaw_deg is the heading, from the local east (+x above the pole,
// the starting point) towards the north (+y), as the sun's azimuth (yaw =
// sun azimuth faces the sun); pitch_deg the angle above the local horizontal,
// −90 straight down to 90 straight up (the screen's right stays horizontal;
// straight down, the heading is at the top of the screen). Above the pole
// this is the camera of `sky render --view camera` with --yaw and --pitch.
// fov_x 90°; the sun as in `sky render`, in the frame of the starting point.
PlanetView planet_viewer_view(const glm::dvec3& eye_km, double yaw_deg, double pitch_deg, double sun_azimuth_deg,
                              double sun_elevation_deg, int width, int height);
// The starting pitch when none is given: 5° above the horizontal, less 1.5
// times the dip of the horizon (acos(R / (R + altitude))), at least −90°. Near
// the ground it is about 5° (the horizon a little below the centre); from high
// up it looks down, the horizon in the upper part of the view and the planet
// below (at 2000 km on Earth: −55.7°, the horizon 40.4° down); from beyond
// about 7800 km on Earth straight down at the disc.
double planet_viewer_default_pitch_deg(double planet_radius_km, double altitude_km);

// Opens a GLFW window with a Dear ImGui panel and runs until it is closed.
// Throws skybake::Error when no display can be opened or the build has no
// window (one line, naming "display").
void run_planet_viewer(const SkyModel& tables, const NeuralSky* net, const ViewerOptions& options);

} // namespace skybake
